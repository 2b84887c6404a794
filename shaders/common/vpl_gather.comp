#version 460
#extension GL_GOOGLE_include_directive : require
// Interleaved VPL gathering (core/vpl/vpl_shading.h; Segovia et al. 2006, Aranha et al. §III-D):
// pixel (x, y) is shaded by the VPLs i = s, s + I^2, s + 2 I^2, ... with s = (x mod I) +
// I (y mod I), and its sum is scaled by N / (its share of the N VPLs), so each sub-image is an
// estimate of the full sum. Per VPL (docs/vpl.md, Eq. 6 in watts):
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

layout(push_constant, std430) uniform Push {
    vec2 bounceScale;    // flux multiplier of bounce 1 and 2 (weights = paper: N1 / N)
    float clampDistance; // d_min in world units (0 = no clamp)
    float biasTexels;    // visibility tolerance in map texels at the receiver
    uint count;          // N VPLs
    uint interleave;     // I
    uint mapResolution;  // paraboloid texels per side
    uint visibility;     // 1 = test layers, 0 = every VPL unshadowed
} pc;

shared vec2 groupSums[64];

// Clustered visibility: is p (normal n) seen from the eye of map `layer`?
float visible(vec3 p, vec3 n, int layer) {
    VplCluster c = clusters[layer];
    if (c.position.w < 0.5) return 0.0;
    mat3 frame = vplFrame(c.normal.xyz);
    vec3 local = frame * (p - c.position.xyz);
    float dist = length(local);
    if (!(dist > 0.0)) return 1.0;
    float r = float(pc.mapResolution);
    // Texel size at p: angular width 4 / (res (1 + r^2)) of the map at its disk point.
    vec2 q = vplParaboloidProject(local / dist);
    float texel = dist * 4.0 / (r * (1.0 + dot(q, q)));
    // Move the receiver one texel along its normal (self-shadowing of the receiving surface).
    local = frame * (p + n * texel - c.position.xyz);
    if (local.z <= 0.0) return 0.0;  // behind the cluster: outside its hemisphere
    dist = length(local);
    q = vplParaboloidProject(local / dist);
    ivec2 t = clamp(ivec2(vplParaboloidUv(q) * r), ivec2(0), ivec2(int(r) - 1));
    float stored = imageLoad(mapPosition, ivec3(t, layer)).w;
    if (stored <= 0.0) return 1.0;  // nothing in that direction
    float cosRecv = abs(dot(n, local / dist));
    float bias = pc.biasTexels * texel / max(cosRecv, 0.2);
    return dist <= stored + bias ? 1.0 : 0.0;
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
        uint share = pc.count > s ? (pc.count - s + stride - 1u) / stride : 0u;
        float minD2 = pc.clampDistance * pc.clampDistance;
        for (uint i = s; i < pc.count; i += stride) {
            Vpl v = vpls[i];
            if (v.position.w < 0.5) continue;
            vec3 d = v.position.xyz - pos.xyz;
            float d2 = dot(d, d);
            if (!(d2 > 1e-20)) continue;  // a VPL on the receiver: no direction, no light
            vec3 l = d * inversesqrt(d2);
            float g = max(dot(n, l), 0.0) * max(dot(v.normal.xyz, -l), 0.0) / VPL_PI;
            if (g <= 0.0) continue;
            int layer = int(v.normal.w);
            if (pc.visibility != 0u && layer >= 0 && visible(pos.xyz, n, layer) == 0.0) continue;
            vec3 phi = v.flux.rgb * (v.flux.w > 1.5 ? pc.bounceScale.y : pc.bounceScale.x) * g;
            vec3 clamped = phi / max(d2, minD2);
            e += clamped;
            removed += phi / d2 - clamped;
        }
        float scale = share > 0u ? float(pc.count) / float(share) : 0.0;
        e *= scale;
        removed *= scale;
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
