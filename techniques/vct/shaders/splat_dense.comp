#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_shader_atomic_float : require
// Dense photon splat with float atomics: see splat_dense_body.glsl.
#include "splat_dense_body.glsl"
