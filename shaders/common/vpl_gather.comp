#version 460
#extension GL_GOOGLE_include_directive : require
// Interleaved VPL gathering (core/vpl/vpl_shading.h; Segovia et al. 2006, Aranha et al. §III-D):
// pixel (x, y) belongs to sub-image s = (x mod I) + I (y mod I) and is shaded by the VPLs of
// subset s only, each weighted I^2, so each sub-image is an unbiased estimate of the full sum.
// The VPL list is Hammersley-ordered sets: vpls[0, firstCount) is one set, the rest are sets of
// groupSize (one per second-bounce cluster; 0 = the rest is one set). Within set j, point k is in
// subset vplInterleaveSubset(k, n, I^2, j, mode), so every subset spreads over the whole RSM or disk
// instead of one strip of it (issue 29). Per VPL (docs/vpl.md, Eq. 6 in watts):
//   E += scale[bounce] flux cos+(theta) cos+(sigma) V / (pi max(d^2, d_min^2))
// V: the paraboloid-map test of the VPL's layer (normal.w >= 0), else 1. The clamp d_min
// removes the 1/d^2 singularity; what it removes is summed per workgroup (clamped energy).
#include "common/vpl.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0, rgba32f) uniform readonly image2D gPosition;
layout(set = 0, binding = 1, rgba32f) uniform readonly image2D gNormal;
layout(set = 0, binding = 2, std430) readonly buffer Vpls { Vpl vpls[]; };
layout(set = 0, binding = 3, std430) readonly buffer Clusters { VplCluster clusters[]; };
layout(set = 0, binding = 4, rgba32f) uniform readonly image2DArray mapPosition;
layout(set = 0, binding = 5, rgba32f) uniform writeonly image2D irradiance;
layout(set = 0, binding = 6, std430) writeonly buffer Partials { vec4 partials[]; };
#include "common/vpl_visibility.glsl"

layout(push_constant, std430) uniform Push {
    vec2 bounceScale;    // flux multiplier of bounce 1 and 2 (weights = paper: N1 / N)
    float clampDistance; // d_min in world units (0 = no clamp)
    float biasTexels;    // visibility tolerance in map texels at the receiver
    uint count;          // N VPLs
    uint interleave;     // I
    uint mapResolution;  // paraboloid texels per side
    uint visibility;     // 1 = test layers, 0 = every VPL unshadowed
    uint firstCount;     // VPLs of the first set (the rest: sets of groupSize)
    uint groupSize;      // VPLs per later set; 0 = one set
    uint subsets;        // vplInterleaveSubset mode (0 fold, 1 blocks, 2 modulo)
    uint pad;
} pc;

shared vec2 groupSums[64];

float visible(vec3 p, vec3 n, int layer) {
    return vplMapVisible(p, n, layer, pc.mapResolution, pc.biasTexels);
}

// Adds VPL i's irradiance at (p, n) to e, and what the near-VPL clamp removed to removed.
void shade(uint i, vec3 p, vec3 n, float minD2, inout vec3 e, inout vec3 removed) {
    Vpl v = vpls[i];
    if (v.position.w < 0.5) return;
    vec3 d = v.position.xyz - p;
    float d2 = dot(d, d);
    if (!(d2 > 1e-20)) return;  // a VPL on the receiver: no direction, no light
    vec3 l = d * inversesqrt(d2);
    float g = max(dot(n, l), 0.0) * max(dot(v.normal.xyz, -l), 0.0) / VPL_PI;
    if (g <= 0.0) return;
    int layer = int(v.normal.w);
    if (pc.visibility != 0u && layer >= 0 && visible(p, n, layer) == 0.0) return;
    vec3 phi = v.flux.rgb * (v.flux.w > 1.5 ? pc.bounceScale.y : pc.bounceScale.x) * g;
    vec3 clamped = phi / max(d2, minD2);
    e += clamped;
    removed += phi / d2 - clamped;
}

// Subset s of the set vpls[base, base + n) whose subsets are rotated by `rotation`.
void shadeSubset(uint base, uint n, uint rotation, uint s, uint stride, vec3 p, vec3 nrm,
                 float minD2, inout vec3 e, inout vec3 removed) {
    bool small = vplSmallSet(n, stride);
    if ((pc.subsets == 0u || small) && pc.subsets != 2u && vplPowerOfTwo(stride)) {
        // fold(k) = (k mod stride) xor fold(k / stride): one k per high part h.
        uint bits = uint(findLSB(stride));
        for (uint h = 0u; (h << bits) < n; ++h) {
            uint k = (h << bits) | (s ^ (rotation & (stride - 1u)) ^ vplFold(h, stride));
            if (k < n) shade(base + k, p, nrm, minD2, e, removed);
        }
        return;
    }
    if (pc.subsets == 2u) {
        for (uint k = (s + stride - rotation % stride) % stride; k < n; k += stride)
            shade(base + k, p, nrm, minD2, e, removed);
        return;
    }
    uint block = vplInterleaveBlock(n, stride);
    if (small) {
        // Row h holds subset s at j = (s - c h - rotation) mod stride (vplInterleaveSubset).
        uint c = vplRowShift(stride), r = rotation % stride;
        for (uint h = 0u; h * stride < n; ++h) {
            uint j = (s + 2u * stride - r - (c * h) % stride) % stride;
            uint k = h * stride + j;
            if (k < n) shade(base + k, p, nrm, minD2, e, removed);
        }
        return;
    }
    for (uint b = (s + stride - rotation % stride) % stride; b * block < n; b += stride)
        for (uint k = b * block; k < min(n, b * block + block); ++k)
            shade(base + k, p, nrm, minD2, e, removed);
}

void main() {
    ivec2 size = imageSize(irradiance);
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    vec3 e = vec3(0.0), removed = vec3(0.0);
    bool inside = all(lessThan(px, size));
    vec4 pos = inside ? imageLoad(gPosition, px) : vec4(0.0);
    if (inside && pos.w > 0.5) {
        vec3 n = imageLoad(gNormal, px).xyz;
        uint stride = pc.interleave * pc.interleave;
        uint s = uint(px.x) % pc.interleave + pc.interleave * (uint(px.y) % pc.interleave);
        float minD2 = pc.clampDistance * pc.clampDistance;
        uint first = min(pc.firstCount, pc.count);
        shadeSubset(0u, first, 0u, s, stride, pos.xyz, n, minD2, e, removed);
        uint group = pc.groupSize > 0u ? pc.groupSize : max(pc.count - first, 1u);
        uint set = 1u;
        for (uint base = first; base < pc.count; base += group, ++set)
            shadeSubset(base, min(group, pc.count - base), set, s, stride, pos.xyz, n, minD2, e,
                        removed);
        e *= float(stride);
        removed *= float(stride);
    }
    if (inside) imageStore(irradiance, px, vec4(e, 1.0));
    // Per-workgroup sums (mean of rgb) of the clamped irradiance and of what the clamp removed.
    uint li = gl_LocalInvocationIndex;
    groupSums[li] = vec2(dot(e, vec3(1.0 / 3.0)), dot(removed, vec3(1.0 / 3.0)));
    barrier();
    for (uint stride = 32u; stride > 0u; stride >>= 1u) {
        if (li < stride) groupSums[li] += groupSums[li + stride];
        barrier();
    }
    if (li == 0u) {
        uint group = gl_WorkGroupID.x + gl_WorkGroupID.y * gl_NumWorkGroups.x;
        partials[group] = vec4(groupSums[0], 0.0, 0.0);
    }
}
