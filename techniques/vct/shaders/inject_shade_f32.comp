#version 460
#extension GL_GOOGLE_include_directive : require
// Voxel shade into an RGBA32F radiance base, float flux sums: see inject_shade_body.glsl.
#define INJECT_FORMAT rgba32f
#include "inject_shade_body.glsl"
