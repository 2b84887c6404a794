// Declarations of the octree's build and injection passes (techniques/vct/svo.cpp).
// Set 0: 0 SvoInfo (uniform), 1 node pool, 2 counters (0 nodes, 1 bricks, 2 overflow, 3 -, then
// per depth d: 4 + 2d first node, 5 + 2d end), 3 occupancy bits (pyramid, one bit per cell),
// 4 irradiance accumulators (3 words per brick sample, by geometry brick; float bits or fixed
// point), 5 radiance brick pool, 6 geometry brick pool, 7 per-light photon ranges (8 words per
// light: 0..2 indirect dispatch x y z, 4 first photon, 5 end; svo_light_ranges.comp), 8 photon
// deposit counts of the light being splatted (1 word per brick sample), 9 normal brick pool
// (geometry pool layout, leaves only: xyz unit mean normal, w its length, as the voxelizer's
// normal volume). Set 1: the voxelizer's albedoOpacity (0) and normal (1). Set 2: photons.
#ifndef GILAB_VCT_SVO_COMMON_GLSL
#define GILAB_VCT_SVO_COMMON_GLSL

#include "photon.glsl"
#include "svo_info.glsl"

layout(set = 0, binding = 0, std140) uniform SvoInfoBlock {
    SvoInfo svo;
};
layout(set = 0, binding = 1, std430) buffer SvoNodes {
    uint svoNodes[];
};
layout(set = 0, binding = 2, std430) buffer SvoCounters {
    uint svoCounters[];
};
layout(set = 0, binding = 3, std430) buffer SvoOccupancy {
    uint svoOccupancy[];
};
#ifdef SVO_FLOAT_ACCUM
layout(set = 0, binding = 4, std430) buffer SvoAccum {
    float svoAccum[];
};
#else
layout(set = 0, binding = 4, std430) buffer SvoAccum {
    uint svoAccum[];
};
#endif
layout(set = 0, binding = 5, rgba16f) uniform image3D svoRadiance;
layout(set = 0, binding = 6, rgba16f) uniform image3D svoGeometry;
layout(set = 0, binding = 7, std430) buffer SvoLights {
    uint svoLights[];
};
#ifdef SVO_FLOAT_ACCUM
layout(set = 0, binding = 8, std430) buffer SvoCounts {
    float svoCount[];  // summed deposit area (m^2) of the light being splatted (svo_splat_body)
};
#else
layout(set = 0, binding = 8, std430) buffer SvoCounts {
    uint svoCount[];
};
#endif
layout(set = 0, binding = 9, rgba8_snorm) uniform image3D svoNormals;

// Words of light l in svoLights (SparseVoxelOctree::kLightWords per light).
#define SVO_LIGHT_WORDS 8u
#define SVO_LIGHT_FIRST 4u
#define SVO_LIGHT_END 5u

#define SVO_NODE(i) svoNodes[i]
#define SVO_INFO svo
#include "svo_tree.glsl"

// Work-group size of every octree pass (SparseVoxelOctree::kGroupSize).
#define SVO_GROUP_SIZE 64

// Targets: 0 flux accumulators (by brick), 1 radiance (isotropic brick at the radiance slot),
// 2 geometry (by brick), 3 directional radiance (6 bricks at slot + face).
#define SVO_TARGET_ACCUM 0u
#define SVO_TARGET_RADIANCE 1u
#define SVO_TARGET_GEOMETRY 2u
#define SVO_TARGET_DIRECTIONAL 3u

// x depth, y axis (0..2), z pass / sub-mode, w target (SVO_TARGET_*)
layout(push_constant, std430) uniform SvoPush {
    uvec4 args;
    vec4 scale;  // x fixed-point units per W/m^2, y W/m^2 per unit, z 1 / pi, w the splatted
                 // light's irradiance cap per photon (fixed point only)
} pc;

// Linear thread index of a 1D launch recorded as a 2D grid (SparseVoxelOctree::dispatchGroups:
// x groups per row, y rows) so that no dimension exceeds maxComputeWorkGroupCount.
uint svoThread() {
    uint row = gl_NumWorkGroups.x * SVO_GROUP_SIZE;
    return gl_GlobalInvocationID.x + gl_GlobalInvocationID.y * row;
}

uint svoLevelBegin(uint depth) { return svoCounters[4u + 2u * depth]; }
uint svoLevelEnd(uint depth) { return svoCounters[5u + 2u * depth]; }

bool svoOccupied(uint depth, uvec3 c) {
    uint n = svo.depthInfo[depth].y;
    uint idx = c.x + n * (c.y + n * c.z);
    return ((svoOccupancy[svo.depthInfo[depth].x + (idx >> 5)] >> (idx & 31u)) & 1u) != 0u;
}

int svoSampleIndex(ivec3 s) { return s.x + 3 * (s.y + 3 * s.z); }

// Node word holding the brick index of `target`: the geometry brick (also indexes the flux
// accumulators) or the radiance slot.
uint svoTargetWord(uint target) {
    return (target == SVO_TARGET_GEOMETRY || target == SVO_TARGET_ACCUM) ? SVO_W_BRICK
                                                                        : SVO_W_RADIANCE;
}
// First texel of brick `index` of the image of `target` (not the accumulators).
ivec3 svoTargetOrigin(uint target, uint index) {
    return target == SVO_TARGET_GEOMETRY ? svoBrickOrigin(index) : svoRadianceOrigin(index);
}

vec4 svoLoad(uint target, ivec3 texel) {
    return target == 2u ? imageLoad(svoGeometry, texel) : imageLoad(svoRadiance, texel);
}
void svoStore(uint target, ivec3 texel, vec4 v) {
    if (target == 2u)
        imageStore(svoGeometry, texel, v);
    else
        imageStore(svoRadiance, texel, v);
}

#endif  // GILAB_VCT_SVO_COMMON_GLSL
