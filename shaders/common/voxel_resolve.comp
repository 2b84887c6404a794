#version 460
#extension GL_GOOGLE_include_directive : require
// Voxel resolve into RGBA16F volumes: see voxel_resolve_body.glsl.
#define VOXEL_FORMAT rgba16f
#include "common/voxel_resolve_body.glsl"
