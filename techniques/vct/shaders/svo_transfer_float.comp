#version 460
#extension GL_GOOGLE_include_directive : require
// Border transfer, float flux accumulators / images: see svo_transfer_body.glsl.
#define SVO_FLOAT_ACCUM
#include "svo_transfer_body.glsl"
