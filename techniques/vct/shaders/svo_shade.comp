#version 460
#extension GL_GOOGLE_include_directive : require
// Octree leaf shading, fixed-point accumulators: see svo_shade_body.glsl.
#include "svo_shade_body.glsl"
