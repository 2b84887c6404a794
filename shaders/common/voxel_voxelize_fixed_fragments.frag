#version 460
#extension GL_GOOGLE_include_directive : require
// Voxelization with fixed-point uint atomics and per-voxel fragment lists: see
// voxel_voxelize_body.glsl.
#define VOXEL_FIXED_POINT
#define VOXEL_FRAGMENT_LISTS
#include "common/voxel_voxelize_body.glsl"
