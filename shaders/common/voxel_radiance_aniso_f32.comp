#version 460
#extension GL_GOOGLE_include_directive : require
// Voxel radiance filter (aniso, rgba32f volumes): see voxel_radiance_aniso_body.glsl.
#define VOXEL_FORMAT rgba32f
#include "common/voxel_radiance_aniso_body.glsl"
