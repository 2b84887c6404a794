#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_shader_atomic_float : require
// Octree photon splat, float atomics: see svo_splat_body.glsl.
#define SVO_FLOAT_ACCUM
#include "svo_splat_body.glsl"
