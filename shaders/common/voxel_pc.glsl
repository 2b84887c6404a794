// Push constants of the voxelization and resolve pipelines (core/voxel/voxelizer.cpp).
#ifndef GILAB_VOXEL_PC_GLSL
#define GILAB_VOXEL_PC_GLSL
#include "common/voxel_grid.glsl"
layout(push_constant, std430) uniform VoxelPush {
    VoxelGridInfo grid;
} pc;
#endif  // GILAB_VOXEL_PC_GLSL
