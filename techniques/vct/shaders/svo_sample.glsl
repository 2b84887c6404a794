// voxelConeSample for the sparse voxel octree (techniques/vct/svo.h, techniques/vct/svo.md;
// Crassin §5, §9, notes 001 §2.8-2.9): quadrilinear lookup = trilinear inside the vertex-centred
// brick of the node whose level matches the lod (hardware linear filter on the brick pool: the
// brick's samples are texel centres, so a position inside the node never leaves its brick), linear
// between the levels floor(lod) and floor(lod) + 1. Descends from the root each time; stops at a
// collapsed node (empty space -> vec4(0)). Level 0 (leaves) is isotropic. Levels >= 1 of an
// anisotropic octree: per axis the directional brick chosen by the sign of `dir` (dir.x < 0 ->
// -X, rays travelling toward -x), weighted by dir^2 / |dir|^2, as the dense sampler
// (voxelConeDirectional in common/voxel_cone_dense.glsl); so lod < 1 blends the isotropic leaf
// level with the first directional level. Facing (Crassin §7, common/voxel_facing.glsl, as the
// dense base samples): a leaf-level sample's colour is weighted by voxelFacing of the trilinear
// normal brick sample divided by the trilinear coverage (voxelMeanNormalFiltered), opacity kept;
// the directional levels are built facing-weighted (svo_filter_aniso.comp). Isotropic octree:
// facing at the leaf level only, `dir` is unused above it.
// Before including, define SVO_SET and SVO_BINDING (layout as
// SparseVoxelOctree::addLayoutBindings: +0 SvoInfo uniform, +1 node pool, +2 radiance bricks,
// +3 leaf normal bricks).
#ifndef GILAB_VCT_SVO_SAMPLE_GLSL
#define GILAB_VCT_SVO_SAMPLE_GLSL

#include "svo_info.glsl"

#if !defined(SVO_SET) || !defined(SVO_BINDING)
#error "define SVO_SET and SVO_BINDING before including svo_sample.glsl"
#endif

layout(set = SVO_SET, binding = SVO_BINDING, std140) uniform SvoSampleInfo {
    SvoInfo svoInfo;
};
layout(set = SVO_SET, binding = SVO_BINDING + 1, std430) readonly buffer SvoSampleNodes {
    uint svoSampleNodes[];
};
layout(set = SVO_SET, binding = SVO_BINDING + 2) uniform sampler3D svoRadiancePool;
layout(set = SVO_SET, binding = SVO_BINDING + 3) uniform sampler3D svoNormalPool;

#define SVO_NODE(i) svoSampleNodes[i]
#define SVO_INFO svoInfo
#include "svo_tree.glsl"
#include "common/voxel_facing.glsl"

// Trilinear lookup at `local` (0..2 per axis) in radiance brick `slot`.
vec4 svoFetch(uint slot, vec3 local) {
    vec3 texel = vec3(svoRadianceOrigin(slot)) + 0.5 + local;
    return textureLod(svoRadiancePool, texel / vec3(textureSize(svoRadiancePool, 0)), 0.0);
}

// Trilinear lookup at `local` in the normal brick of geometry brick `brick` (leaves).
vec4 svoFetchNormal(uint brick, vec3 local) {
    vec3 texel = vec3(svoBrickOrigin(brick)) + 0.5 + local;
    return textureLod(svoNormalPool, texel / vec3(textureSize(svoNormalPool, 0)), 0.0);
}

// Level l sample (spacing v0 2^l) at grid position g (voxel units, centres at i + 0.5) for a
// cone travelling along `dir`.
vec4 svoSampleLevel(vec3 g, uint level, vec3 dir) {
    uint leafDepth = svoInfo.dims.y;
    uint depth = leafDepth - level;
    float n = float(svoInfo.dims.x);
    // Level-l lattice coordinate: sample s sits at grid position s 2^l + 0.5 (clamp to edge
    // below the first voxel centre, as the dense volumes' sampler does).
    vec3 u = clamp(g - 0.5, vec3(0.0), vec3(n)) / float(1u << level);
    uint cells = 1u << depth;
    uvec3 cell = min(uvec3(floor(u * 0.5)), uvec3(cells - 1u));
    uint node = svoFindNode(cell, depth);
    if (node == SVO_NONE) return vec4(0.0);
    uint slot = svoWord(node, SVO_W_RADIANCE);
    if (slot == SVO_NONE) return vec4(0.0);
    vec3 local = clamp(u - 2.0 * vec3(cell), vec3(0.0), vec3(2.0));
    if (level == 0u) {
        vec4 s = svoFetch(slot, local);
        uint brick = svoWord(node, SVO_W_BRICK);
        if (brick != SVO_NONE)
            s.rgb *= voxelFacing(voxelMeanNormalFiltered(svoFetchNormal(brick, local), s.a), dir);
        return s;
    }
    if (!svoAnisotropic()) return svoFetch(slot, local);
    vec3 w = dir * dir;
    float wsum = w.x + w.y + w.z;
    if (!(wsum > 1e-12)) return vec4(0.0);
    vec4 sx = svoFetch(slot + (dir.x < 0.0 ? 0u : 1u), local);
    vec4 sy = svoFetch(slot + (dir.y < 0.0 ? 2u : 3u), local);
    vec4 sz = svoFetch(slot + (dir.z < 0.0 ? 4u : 5u), local);
    return (w.x * sx + w.y * sy + w.z * sz) / wsum;
}

vec4 voxelConeSample(vec3 worldPos, float lod, vec3 dir) {
    vec3 g = (worldPos - svoInfo.originVoxelSize.xyz) / svoInfo.originVoxelSize.w;
    float n = float(svoInfo.dims.x);
    if (any(lessThan(g, vec3(0.0))) || any(greaterThan(g, vec3(n)))) return vec4(0.0);
    float maxLevel = float(svoInfo.dims.y);
    lod = clamp(lod, 0.0, maxLevel);
    uint l0 = uint(floor(lod));
    float f = lod - float(l0);
    vec4 s = svoSampleLevel(g, l0, dir);
    if (f > 0.0 && l0 < svoInfo.dims.y) s = mix(s, svoSampleLevel(g, l0 + 1u, dir), f);
    s = max(s, vec4(0.0));
    if (!(s.a > 0.0)) return vec4(0.0);
    return vec4(s.rgb, min(s.a, 1.0));
}

#include "common/voxel_cone.glsl"

#endif  // GILAB_VCT_SVO_SAMPLE_GLSL
