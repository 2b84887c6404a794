// Shared declarations of vct's dense splat and shade passes (techniques/vct/light_injection.cpp).
// Set 0: binding 0 photons, 1 the voxelizer's albedoOpacity volume, 2 three flux planes of N^3
// words (r, g, b; float sums, or uint fixed point when INJECT_FIXED_POINT), 3 the radiance
// volume's base (shade only; INJECT_FORMAT = rgba16f or rgba32f).
#ifndef GILAB_VCT_INJECT_COMMON_GLSL
#define GILAB_VCT_INJECT_COMMON_GLSL

#include "common/voxel_grid.glsl"
#include "vct/photon.glsl"

layout(set = 0, binding = 0, std430) readonly buffer Photons {
    Photon photons[];
};
layout(set = 0, binding = 1) uniform sampler3D voxelAlbedoOpacity;
#ifdef INJECT_FIXED_POINT
layout(set = 0, binding = 2, std430) buffer FluxPlanes {
    uint v[];
} fluxPlanes[3];
#else
layout(set = 0, binding = 2, std430) buffer FluxPlanes {
    float v[];
} fluxPlanes[3];
#endif

layout(push_constant, std430) uniform InjectPush {
    VoxelGridInfo grid;
    vec4 scale;    // x fixed-point units per W, y W per unit
    uvec4 counts;  // x photon count
} pc;

#endif  // GILAB_VCT_INJECT_COMMON_GLSL
