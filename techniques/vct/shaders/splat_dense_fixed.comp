#version 460
#extension GL_GOOGLE_include_directive : require
// Dense photon splat with 32-bit fixed-point uint atomics: see splat_dense_body.glsl.
#define INJECT_FIXED_POINT
#include "splat_dense_body.glsl"
