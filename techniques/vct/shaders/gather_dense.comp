#version 460
#extension GL_GOOGLE_include_directive : require
// vct per-pixel gather on the dense radiance pyramid (gilab::VoxelRadiance): set 0 as
// gather_inputs.glsl, set 1 = VoxelRadiance::addLayoutBindings(first = 0). See gather_body.glsl.
#include "gather_inputs.glsl"
#define VOXEL_CONE_SET 1
#define VOXEL_CONE_BINDING 0
#include "common/voxel_cone_dense.glsl"
#include "gather_body.glsl"
