// voxelConeSample for gilab::VoxelRadiance (dense N^3 base + 6 directional (N/2)^3 volumes with
// mips, stacked in one atlas; docs/voxel_cone_tracing.md, notes 003 §2.8 and §7.1). Before
// including, define
//     #define VOXEL_CONE_SET <set>
//     #define VOXEL_CONE_BINDING <first binding>   (layout as VoxelRadiance::addLayoutBindings)
//     VoxelGridInfo voxelConeGrid();               (shaders/common/voxel_grid.glsl)
//     bool voxelConeAnisotropic();
// Optional: #define VOXEL_CONE_NO_BASE when the same dispatch writes base() (never sample it;
// lod < 1 then reads directional level 0).
// Then this file provides voxelConeSample and includes voxel_cone.glsl (traceCone, ...).
// Level mapping: lod < 1 mixes base and directional level 0 by lod; lod >= 1 reads directional
// level lod - 1 (hardware linear between mips). Branch-free: lavapipe executes both sides of a
// branch, so every sample reads the directional level max(lod - 1, 0) and the base.
// Directional sample = sum over axes of dir^2 times the face for rays travelling along dir
// (dir.x < 0 -> -X face = index 0).
#ifndef GILAB_VOXEL_CONE_DENSE_GLSL
#define GILAB_VOXEL_CONE_DENSE_GLSL

#include "common/voxel_grid.glsl"

#if !defined(VOXEL_CONE_SET) || !defined(VOXEL_CONE_BINDING)
#error "define VOXEL_CONE_SET and VOXEL_CONE_BINDING before including voxel_cone_dense.glsl"
#endif

layout(set = VOXEL_CONE_SET, binding = VOXEL_CONE_BINDING) uniform sampler3D voxelConeBase;
layout(set = VOXEL_CONE_SET, binding = VOXEL_CONE_BINDING + 1) uniform sampler3D voxelConeFaces;
layout(set = VOXEL_CONE_SET, binding = VOXEL_CONE_BINDING + 2) uniform sampler3D voxelConeNormals;

#include "common/voxel_facing.glsl"

// One slab of the filtered atlas (6 faces -X,+X,-Y,+Y,-Z,+Z stacked in z, or 1 isotropic) at
// filtered level `level`. z is clamped half a texel of the coarser level inside the slab, so
// the hardware filter never mixes two faces (z is clamp-to-edge, x and y clamp-to-border).
vec4 voxelConeSlab(vec3 uvw, float level, float slab, float slabs) {
    float n = float(voxelResolution(voxelConeGrid()) / 2u);
    float halfTexel = 0.5 * exp2(ceil(level)) / n;
    float z = clamp(uvw.z, min(halfTexel, 0.5), max(1.0 - halfTexel, 0.5));
    return textureLod(voxelConeFaces, vec3(uvw.xy, (slab + z) / slabs), level);
}

// Directional (or isotropic) filtered volume at filtered level `level` (0 = (N/2)^3): per axis
// the face its sign selects (chosen by coordinates: no branch, one fetch per axis), weighted
// by dir^2.
vec4 voxelConeDirectional(vec3 uvw, float level, vec3 dir) {
    if (!voxelConeAnisotropic()) return voxelConeSlab(uvw, level, 0.0, 1.0);
    vec3 w = dir * dir;
    float wsum = w.x + w.y + w.z;
    if (!(wsum > 1e-12)) return vec4(0.0);
    vec3 face = vec3(0.0, 2.0, 4.0) + step(vec3(0.0), dir);  // dir < 0: -axis face
    vec4 s = w.x * voxelConeSlab(uvw, level, face.x, 6.0);
    s += w.y * voxelConeSlab(uvw, level, face.y, 6.0);
    s += w.z * voxelConeSlab(uvw, level, face.z, 6.0);
    return s / wsum;
}

vec4 voxelConeSample(vec3 worldPos, float lod, vec3 dir) {
    vec3 uvw = voxelWorldToUvw(voxelConeGrid(), worldPos);
    if (any(lessThan(uvw, vec3(0.0))) || any(greaterThan(uvw, vec3(1.0)))) return vec4(0.0);
    lod = max(lod, 0.0);
    vec4 s;
#ifdef VOXEL_CONE_NO_BASE
    // The includer writes the base volume in this dispatch (e.g. a voxel bounce pass): never
    // read it; lod < 1 takes directional level 0.
    s = voxelConeDirectional(uvw, max(lod - 1.0, 0.0), dir);
#else
    // Shade the base toward the cone (the directional levels are built facing-weighted)
    vec4 base = textureLod(voxelConeBase, uvw, 0.0);
    vec4 nl = textureLod(voxelConeNormals, uvw, 0.0);
    base.rgb *= voxelFacing(voxelMeanNormalFiltered(nl, base.a), dir);
    vec4 directional = voxelConeDirectional(uvw, max(lod - 1.0, 0.0), dir);
    s = mix(base, directional, clamp(lod, 0.0, 1.0));
#endif
    // Empty samples carry no colour; no negative or non-finite values leave here.
    s = max(s, vec4(0.0));
    if (!(s.a > 0.0)) return vec4(0.0);
    return vec4(s.rgb, min(s.a, 1.0));
}

// Samples at level >= 1 read the directional levels only (voxel_cone.glsl's second loop).
vec4 voxelConeSampleCoarse(vec3 worldPos, float lod, vec3 dir) {
    vec3 uvw = voxelWorldToUvw(voxelConeGrid(), worldPos);
    if (any(lessThan(uvw, vec3(0.0))) || any(greaterThan(uvw, vec3(1.0)))) return vec4(0.0);
    vec4 s = max(voxelConeDirectional(uvw, max(lod - 1.0, 0.0), dir), vec4(0.0));
    if (!(s.a > 0.0)) return vec4(0.0);
    return vec4(s.rgb, min(s.a, 1.0));
}

#define VOXEL_CONE_HAS_COARSE_SAMPLE
#include "common/voxel_cone.glsl"

#endif  // GILAB_VOXEL_CONE_DENSE_GLSL
