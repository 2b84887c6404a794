#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_shader_atomic_float : require
// Voxelization with float atomics and per-voxel fragment lists: see voxel_voxelize_body.glsl.
#define VOXEL_FRAGMENT_LISTS
#include "common/voxel_voxelize_body.glsl"
