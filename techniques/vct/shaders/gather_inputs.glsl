// Set 0 of vct's per-pixel gather (techniques/vct/vct.cpp): the inputs every storage variant
// shares. Include it first, then define voxelConeSample (dense: common/voxel_cone_dense.glsl
// with VOXEL_CONE_SET 1, VOXEL_CONE_BINDING 0; octree: techniques/vct/shaders/svo_gather.comp), then include
// vct/gather_body.glsl. See gather_body.glsl for the full contract.
//   binding 0..3  G-buffer position, normal, albedo, material (rgba32f storage images, GENERAL)
//   binding 4     indirect output (rgba32f storage image, GENERAL)
//   binding 5     ambient-occlusion debug output (rgba32f storage image, GENERAL)
//   binding 6     uniform block GatherParams (std140), mirrored by GpuGatherParams in vct.cpp
#ifndef GILAB_VCT_GATHER_INPUTS_GLSL
#define GILAB_VCT_GATHER_INPUTS_GLSL

#include "common/voxel_grid.glsl"

#define GATHER_FLAG_SPECULAR 1u
#define GATHER_FLAG_AO 2u
#define GATHER_FLAG_ANISOTROPIC 4u
#define GATHER_FLAG_LEVEL0_RAYS 8u  // control: sizeFlags.w rays at level 0 instead of the cones

layout(set = 0, binding = 0, rgba32f) uniform readonly image2D gPosition;
layout(set = 0, binding = 1, rgba32f) uniform readonly image2D gNormal;
layout(set = 0, binding = 2, rgba32f) uniform readonly image2D gAlbedo;
layout(set = 0, binding = 3, rgba32f) uniform readonly image2D gMaterial;
layout(set = 0, binding = 4, rgba32f) uniform writeonly image2D outIndirect;
layout(set = 0, binding = 5, rgba32f) uniform writeonly image2D outAo;

layout(set = 0, binding = 6, std140) uniform GatherParams {
    // ConeTraceParams of common/voxel_cone.glsl
    vec4 gridMinV0;    // xyz grid minimum corner, w v0
    vec4 gridMaxStep;  // xyz grid maximum corner, w step factor
    vec4 distances;    // x max distance (world), y t0 (world), z opacity cutoff, w AO lambda
    vec4 misc;         // x lod bias, y lift factor (voxel_cone.glsl)
    // ConeSetData of common/cone_set.glsl
    vec4 cones[16];  // xyz tangent-space direction, w weight (sum = pi)
    vec4 coneInfo;   // x count, y tan(aperture / 2)
    vec4 cameraPosition;  // xyz world
    uvec4 sizeFlags;      // x width, y height, z GATHER_FLAG_* bits, w level-0 control rays
    vec4 specular;        // x min aperture (rad), y max aperture (rad), z origin offset (world)
    VoxelGridInfo grid;   // the voxel grid (origin, v0, N)
} gather;

// For common/voxel_cone_dense.glsl (and any storage that wants them).
VoxelGridInfo voxelConeGrid() { return gather.grid; }
bool voxelConeAnisotropic() { return (gather.sizeFlags.z & GATHER_FLAG_ANISOTROPIC) != 0u; }

#endif  // GILAB_VCT_GATHER_INPUTS_GLSL
