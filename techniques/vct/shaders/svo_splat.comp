#version 460
#extension GL_GOOGLE_include_directive : require
// Octree photon splat, fixed-point accumulators: see svo_splat_body.glsl.
#include "svo_splat_body.glsl"
