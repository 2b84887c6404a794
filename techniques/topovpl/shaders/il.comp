#version 460
#extension GL_GOOGLE_include_directive : require
// Indirect lighting (IL; Noël & Biri 2014 §V-D): every pixel walks the entry list of its
// geometry cluster. An entry without a gate is visible (same visibility cluster); an entry with
// a gate is visible when the pixel is seen from the VPL through that gate (exact test E7). A VPL
// is visible (E6) when any of its consecutive entries is, and then adds, in watts
// (docs/vpl.md, E5 with a diffuse receiver):
//   E += flux cos+(theta) cos+(sigma) / (pi max(d^2, d_min^2))
// The clamp d_min removes the 1/d^2 singularity near a VPL; what it removes is summed per
// workgroup and read back (clamped energy). Output: outgoing radiance albedo / pi x E.
#include "common/vpl.glsl"
#include "topovpl.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0, rgba32f) uniform readonly image2D gPosition;
layout(set = 0, binding = 1, rgba32f) uniform readonly image2D gNormal;
layout(set = 0, binding = 2, rgba32f) uniform readonly image2D gAlbedo;
layout(set = 0, binding = 3, r32ui) uniform readonly uimage2D geoImage;
layout(set = 0, binding = 4, std430) readonly buffer Vpls { Vpl vpls[]; };
layout(set = 0, binding = 5, std430) readonly buffer Gates { TopoGate gates[]; };
layout(set = 0, binding = 6, std430) readonly buffer Counts { uint counts[]; };
layout(set = 0, binding = 7, std430) readonly buffer Offsets { uint offsets[]; };
layout(set = 0, binding = 8, std430) readonly buffer Entries { uvec2 entries[]; };
layout(set = 0, binding = 9, rgba32f) uniform writeonly image2D indirect;
layout(set = 0, binding = 10, std430) writeonly buffer Partials { vec4 partials[]; };

layout(push_constant, std430) uniform Push {
    float clampDistance;  // d_min in world units (0 = no clamp)
    uint capacity;        // entries in the buffer (entries beyond it were not written)
} pc;

shared vec2 groupSums[64];

void main() {
    ivec2 size = imageSize(indirect);
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    bool inside = all(lessThan(px, size));
    vec3 e = vec3(0.0), removed = vec3(0.0), albedo = vec3(0.0);
    uint k = inside ? imageLoad(geoImage, px).x : TOPO_NONE;
    if (k != TOPO_NONE) {
        vec3 p = imageLoad(gPosition, px).xyz;
        vec3 n = imageLoad(gNormal, px).xyz;
        albedo = imageLoad(gAlbedo, px).rgb;
        float minD2 = pc.clampDistance * pc.clampDistance;
        uint begin = offsets[k];
        uint end = begin + counts[k];
        if (end < begin || end > pc.capacity) end = pc.capacity;  // overflowed lists
        uint last = TOPO_NONE;
        bool lit = false;
        for (uint j = begin; j < end; ++j) {
            uvec2 entry = entries[j];
            if (entry.x == last && lit) continue;  // already lit through another gate
            if (entry.x != last) {
                last = entry.x;
                lit = false;
            }
            Vpl v = vpls[entry.x];
            if (entry.y != TOPO_NONE && !topoThroughGate(v.position.xyz, p, gates[entry.y]))
                continue;
            lit = true;
            vec3 d = v.position.xyz - p;
            float d2 = dot(d, d);
            if (!(d2 > 1e-20)) continue;  // a VPL on the receiver: no direction, no light
            vec3 l = d * inversesqrt(d2);
            float g = max(dot(n, l), 0.0) * max(dot(v.normal.xyz, -l), 0.0) / VPL_PI;
            if (g <= 0.0) continue;
            vec3 phi = v.flux.rgb * g;
            vec3 clamped = phi / max(d2, minD2);
            e += clamped;
            removed += phi / d2 - clamped;
        }
    }
    if (inside) imageStore(indirect, px, vec4(albedo / VPL_PI * e, 1.0));
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
