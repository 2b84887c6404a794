#version 460
#extension GL_GOOGLE_include_directive : require
// Diagnostic, not part of the method (issue 30): how much of the unshadowed VPL light do pairs
// of the same visibility cluster carry? Every covered pixel against every VPL, unshadowed, with
// il.comp's formula and near-VPL clamp; per workgroup the sums (mean of rgb) of the outgoing
// radiance of all pairs and of same-cluster pairs. Same-cluster pairs are the ones the method
// lights without a gate (§V-C), so this share bounds what it can keep without its gates.
#include "common/vpl.glsl"
#include "topovpl.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0, rgba32f) uniform readonly image2D gPosition;
layout(set = 0, binding = 1, rgba32f) uniform readonly image2D gNormal;
layout(set = 0, binding = 2, rgba32f) uniform readonly image2D gAlbedo;
layout(set = 0, binding = 3, r32ui) uniform readonly uimage2D clusterImage;
layout(set = 0, binding = 4, std430) readonly buffer Vpls { Vpl vpls[]; };
layout(set = 0, binding = 5, std430) readonly buffer VplClusters { uint vplCluster[]; };
layout(set = 0, binding = 6, std430) writeonly buffer Partials { vec4 partials[]; };

layout(push_constant, std430) uniform Push {
    float clampDistance;  // d_min in world units (0 = no clamp)
    uint vplCount;
} pc;

shared vec2 groupSums[64];

void main() {
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    vec3 total = vec3(0.0), same = vec3(0.0);
    if (all(lessThan(px, imageSize(gPosition)))) {
        vec4 p = imageLoad(gPosition, px);
        if (p.w > 0.5) {
            vec3 n = imageLoad(gNormal, px).xyz;
            vec3 albedo = imageLoad(gAlbedo, px).rgb;
            uint c = imageLoad(clusterImage, px).x;
            float minD2 = pc.clampDistance * pc.clampDistance;
            for (uint i = 0u; i < pc.vplCount; ++i) {
                Vpl v = vpls[i];
                if (v.position.w < 0.5) continue;
                vec3 d = v.position.xyz - p.xyz;
                float d2 = dot(d, d);
                if (!(d2 > 1e-20)) continue;
                vec3 l = d * inversesqrt(d2);
                float g = max(dot(n, l), 0.0) * max(dot(v.normal.xyz, -l), 0.0) / VPL_PI;
                if (g <= 0.0) continue;
                vec3 radiance = albedo / VPL_PI * v.flux.rgb * g / max(d2, minD2);
                total += radiance;
                if (c != TOPO_NONE && vplCluster[i] == c) same += radiance;
            }
        }
    }
    uint li = gl_LocalInvocationIndex;
    groupSums[li] = vec2(dot(total, vec3(1.0 / 3.0)), dot(same, vec3(1.0 / 3.0)));
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
