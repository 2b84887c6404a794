#version 460
#extension GL_GOOGLE_include_directive : require
// Voxel resolve into RGBA32F volumes: see voxel_resolve_body.glsl.
#define VOXEL_FORMAT rgba32f
#include "common/voxel_resolve_body.glsl"
