// Voxelization, stage 3 (the body of voxelize.frag and voxel_voxelize_fixed.frag): one fragment
// = one voxel column of the dominant projection. The triangle's plane spans up to 3 voxels in
// depth inside one pixel (|dw/du| + |dw/dv| <= 2 for the dominant axis), so every voxel of the
// column between the plane's depth range over the pixel square is tested against the triangle
// exactly (SAT) and accumulated once: coverage is conservative and exact up to round-off.
// Attributes come from the triangle at the pixel centre's projection (clamped into the
// triangle); textures are sampled at LOD 0. Averaging is by atomic sums (notes 003 §2.1 uses an
// RGBA8 compare-and-swap running average that drops updates after 255 tries; sums lose none).
#include "common/scene.glsl"
#include "common/voxel_pc.glsl"
#include "common/voxel_sat.glsl"

#ifndef VOXEL_FRAGMENT_LISTS
// One buffer per accumulator word (VOXEL_ACC_WORDS planes of N^3 values), so each binding stays
// under maxStorageBufferRange (128 MiB on lavapipe) up to 256^3.
#ifdef VOXEL_FIXED_POINT
layout(set = 1, binding = 0, std430) buffer VoxelAccumulators {
    uint v[];
} voxelAcc[VOXEL_ACC_WORDS];
#else
layout(set = 1, binding = 0, std430) buffer VoxelAccumulators {
    float v[];
} voxelAcc[VOXEL_ACC_WORDS];
#endif

// Constant plane indices only (no descriptor-array dynamic indexing needed).
#define VOXEL_ADD3(first, i, value)                  \
    atomicAdd(voxelAcc[first].v[i], (value).x);     \
    atomicAdd(voxelAcc[first + 1].v[i], (value).y); \
    atomicAdd(voxelAcc[first + 2].v[i], (value).z)

void accumulate(uint i, vec3 albedo, vec3 normal, vec3 emission) {
#ifdef VOXEL_FIXED_POINT
    uvec3 al = uvec3(round(clamp(albedo, 0.0, 1.0) * VOXEL_FIXED_ALBEDO_SCALE));
    // Signed sums in two's complement.
    uvec3 nr = uvec3(ivec3(round(clamp(normal, -1.0, 1.0) * VOXEL_FIXED_NORMAL_SCALE)));
    uvec3 em = uvec3(round(clamp(emission, 0.0, 65535.0) * VOXEL_FIXED_EMISSION_SCALE));
    VOXEL_ADD3(0, i, al);
    VOXEL_ADD3(3, i, nr);
    VOXEL_ADD3(6, i, em);
    atomicAdd(voxelAcc[9].v[i], 1u);
#else
    VOXEL_ADD3(0, i, albedo);
    VOXEL_ADD3(3, i, normal);
    VOXEL_ADD3(6, i, emission);
    atomicAdd(voxelAcc[9].v[i], 1.0);
#endif
}
#else
// Fragment-list mode (Cosin Ayerbe & Patow 2022 §4.1, Fig. 3; core/voxel/voxel_fragments.h),
// instead of the accumulators: a linear fragment buffer appended with an atomic counter and one
// list head per voxel, linked by atomicExchange. Fragments past the capacity are counted, not
// written (the host re-runs).
#include "common/voxel_fragments.glsl"
layout(set = 1, binding = 0, std430) buffer VoxelHeads {
    uint heads[];
};
layout(set = 1, binding = 1, std430) buffer VoxelFragmentBuffer {
    VoxelFragment fragments[];
};
layout(set = 1, binding = 2, std430) buffer VoxelFragmentCounter {
    uint fragmentCount;
    uint fragmentCapacity;
};

void appendFragment(uint voxel, vec3 position, vec3 normal, vec3 albedo) {
    uint slot = atomicAdd(fragmentCount, 1u);
    if (slot >= fragmentCapacity) return;
    uint next = atomicExchange(heads[voxel], slot);
    fragments[slot] = voxelPackFragment(position, normal, albedo, next);
}
#endif

layout(location = 0) flat in uint inTriangle;
layout(location = 1) flat in uint inAxis;
layout(location = 2) flat in vec3 inP0;
layout(location = 3) flat in vec3 inP1;
layout(location = 4) flat in vec3 inP2;
layout(location = 5) flat in vec4 inAabb;

const float kEps = 1e-4;  // voxel units: touching within round-off counts as overlap

vec3 swizzleFromAxis(vec3 p, uint a) { return a == 0u ? p.zxy : (a == 1u ? p.yzx : p); }

void main() {
    vec2 lo = floor(gl_FragCoord.xy), hi = lo + 1.0;
    if (any(lessThan(hi, inAabb.xy - kEps)) || any(greaterThan(lo, inAabb.zw + kEps))) return;
    vec3 n = cross(inP1 - inP0, inP2 - inP0);
    if (abs(n.z) < 1e-20) return;
    // Depth of the plane w(u, v) at the pixel's corners, clamped to the triangle's depth range.
    vec2 grad = -n.xy / n.z;
    float wc = inP0.z + dot(grad, (lo + 0.5) - inP0.xy);
    float spread = 0.5 * (abs(grad.x) + abs(grad.y));
    float wMin = max(wc - spread, min(inP0.z, min(inP1.z, inP2.z)));
    float wMax = min(wc + spread, max(inP0.z, max(inP1.z, inP2.z)));
    int res = int(voxelResolution(pc.grid));
    int z0 = max(0, int(floor(wMin - kEps))), z1 = min(res - 1, int(floor(wMax + kEps)));
    if (z1 < z0) return;

    // Barycentrics of the pixel centre in the projected triangle, clamped into it.
    vec2 q = lo + 0.5;
    vec2 e1 = inP1.xy - inP0.xy, e2 = inP2.xy - inP0.xy, d = q - inP0.xy;
    float det = e1.x * e2.y - e1.y * e2.x;
    vec2 b = vec2(d.x * e2.y - d.y * e2.x, e1.x * d.y - e1.y * d.x) / det;
    vec3 bary = max(vec3(1.0 - b.x - b.y, b.x, b.y), vec3(0.0));
    bary /= max(bary.x + bary.y + bary.z, 1e-20);

    uvec3 t = fetchTriangle(inTriangle);
    SceneVertex v0 = fetchVertex(t.x), v1 = fetchVertex(t.y), v2 = fetchVertex(t.z);
    vec2 uv = bary.x * v0.uv + bary.y * v1.uv + bary.z * v2.uv;
    Material m = fetchMaterial(inTriangle);
    vec4 baseColor = sampleBaseColor(m, uv);
    if ((m.flags & MATERIAL_ALPHA_MASK) != 0u && baseColor.a < m.alphaCutoff) return;
    vec3 normal = bary.x * v0.normal + bary.y * v1.normal + bary.z * v2.normal;
    if (dot(normal, normal) < 1e-24) normal = triangleGeometricNormal(inTriangle);
    normal = normalize(normal);
    vec3 emission = sampleEmission(m, uv);

    const vec3 halfSize = vec3(0.5 + kEps);
    for (int z = z0; z <= z1 && z <= z0 + 4; ++z) {
        vec3 cell = vec3(lo, float(z));
        if (!voxelTriangleBoxOverlap(cell + 0.5, halfSize, inP0, inP1, inP2)) continue;
        ivec3 c = ivec3(swizzleFromAxis(cell, inAxis));
#ifndef VOXEL_FRAGMENT_LISTS
        accumulate(voxelLinearIndex(pc.grid, c), baseColor.rgb, normal, emission);
#else
        vec3 position = bary.x * v0.position + bary.y * v1.position + bary.z * v2.position;
        appendFragment(voxelLinearIndex(pc.grid, c), position, normal, baseColor.rgb);
#endif
    }
}
