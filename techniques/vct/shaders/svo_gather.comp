#version 460
#extension GL_GOOGLE_include_directive : require
// vct per-pixel gather on the sparse voxel octree: set 0 as gather_inputs.glsl, set 1 =
// SparseVoxelOctree::addLayoutBindings(first = 0). See gather_body.glsl and svo_sample.glsl.
#include "gather_inputs.glsl"
#define SVO_SET 1
#define SVO_BINDING 0
#include "svo_sample.glsl"
#include "gather_body.glsl"
