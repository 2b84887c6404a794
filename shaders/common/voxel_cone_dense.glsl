// voxelConeSample for gilab::VoxelRadiance (dense N^3 base + 6 directional (N/2)^3 volumes with
// mips; docs/voxel_cone_tracing.md, notes 003 §2.8 and §7.1). Before including, define
//     #define VOXEL_CONE_SET <set>
//     #define VOXEL_CONE_BINDING <first binding>   (layout as VoxelRadiance::addLayoutBindings)
//     VoxelGridInfo voxelConeGrid();               (shaders/common/voxel_grid.glsl)
//     bool voxelConeAnisotropic();
// Optional: #define VOXEL_CONE_NO_BASE when the same dispatch writes base() (never sample it;
// lod < 1 then reads directional level 0).
// Then this file provides voxelConeSample and includes voxel_cone.glsl (traceCone, ...).
// Level mapping: lod < 1 mixes base and directional level 0 by lod; lod >= 1 reads directional
// level lod - 1 (hardware linear between mips). Directional sample = sum over axes of dir^2 times
// the face for rays travelling along dir (dir.x < 0 -> -X face = index 0).
#ifndef GILAB_VOXEL_CONE_DENSE_GLSL
#define GILAB_VOXEL_CONE_DENSE_GLSL

#include "common/voxel_grid.glsl"

#if !defined(VOXEL_CONE_SET) || !defined(VOXEL_CONE_BINDING)
#error "define VOXEL_CONE_SET and VOXEL_CONE_BINDING before including voxel_cone_dense.glsl"
#endif

layout(set = VOXEL_CONE_SET, binding = VOXEL_CONE_BINDING) uniform sampler3D voxelConeBase;
layout(set = VOXEL_CONE_SET, binding = VOXEL_CONE_BINDING + 1) uniform sampler3D voxelConeNegX;
layout(set = VOXEL_CONE_SET, binding = VOXEL_CONE_BINDING + 2) uniform sampler3D voxelConePosX;
layout(set = VOXEL_CONE_SET, binding = VOXEL_CONE_BINDING + 3) uniform sampler3D voxelConeNegY;
layout(set = VOXEL_CONE_SET, binding = VOXEL_CONE_BINDING + 4) uniform sampler3D voxelConePosY;
layout(set = VOXEL_CONE_SET, binding = VOXEL_CONE_BINDING + 5) uniform sampler3D voxelConeNegZ;
layout(set = VOXEL_CONE_SET, binding = VOXEL_CONE_BINDING + 6) uniform sampler3D voxelConePosZ;

// Directional (or isotropic) filtered volume at filtered level `level` (0 = (N/2)^3).
vec4 voxelConeDirectional(vec3 uvw, float level, vec3 dir) {
    if (!voxelConeAnisotropic()) return textureLod(voxelConeNegX, uvw, level);
    vec3 w = dir * dir;
    vec4 sx = dir.x < 0.0 ? textureLod(voxelConeNegX, uvw, level)
                          : textureLod(voxelConePosX, uvw, level);
    vec4 sy = dir.y < 0.0 ? textureLod(voxelConeNegY, uvw, level)
                          : textureLod(voxelConePosY, uvw, level);
    vec4 sz = dir.z < 0.0 ? textureLod(voxelConeNegZ, uvw, level)
                          : textureLod(voxelConePosZ, uvw, level);
    float wsum = w.x + w.y + w.z;
    if (!(wsum > 1e-12)) return vec4(0.0);
    return (w.x * sx + w.y * sy + w.z * sz) / wsum;
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
    if (lod < 1.0) {
        vec4 base = textureLod(voxelConeBase, uvw, 0.0);
        s = lod > 0.0 ? mix(base, voxelConeDirectional(uvw, 0.0, dir), lod) : base;
    } else {
        s = voxelConeDirectional(uvw, lod - 1.0, dir);
    }
#endif
    // Empty samples carry no colour; no negative or non-finite values leave here.
    s = max(s, vec4(0.0));
    if (!(s.a > 0.0)) return vec4(0.0);
    return vec4(s.rgb, min(s.a, 1.0));
}

#include "common/voxel_cone.glsl"

#endif  // GILAB_VOXEL_CONE_DENSE_GLSL
