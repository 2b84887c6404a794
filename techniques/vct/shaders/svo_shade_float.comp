#version 460
#extension GL_GOOGLE_include_directive : require
// Octree leaf shading, float accumulators: see svo_shade_body.glsl.
#define SVO_FLOAT_ACCUM
#include "svo_shade_body.glsl"
