#version 460
#extension GL_GOOGLE_include_directive : require
// Voxelization in fragment-list mode (uint atomics only, no accumulators): see
// voxel_voxelize_body.glsl.
#define VOXEL_FRAGMENT_LISTS
#include "common/voxel_voxelize_body.glsl"
