#version 460
#extension GL_GOOGLE_include_directive : require
// Voxelization with fixed-point uint atomics (devices without float atomics): scales in
// voxel_grid.glsl, see voxel_voxelize_body.glsl.
#define VOXEL_FIXED_POINT
#include "common/voxel_voxelize_body.glsl"
