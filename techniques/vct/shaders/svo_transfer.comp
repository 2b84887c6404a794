#version 460
#extension GL_GOOGLE_include_directive : require
// Border transfer, fixed-point flux accumulators / images: see svo_transfer_body.glsl.
#include "svo_transfer_body.glsl"
