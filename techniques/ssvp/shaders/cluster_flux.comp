#version 460
#extension GL_GOOGLE_include_directive : require
// After map_members.comp moved members (map_members = reassign): each cluster's summed flux and
// member count from the new assignment, so the second bounce re-emits every member's flux from
// the map that sees it (second_bounce.comp). The eyes and maps stay as rendered. One workgroup,
// thread j = cluster j (C <= 64).
#include "kmeans_common.glsl"

layout(local_size_x = 64) in;

void main() {
    uint j = gl_LocalInvocationID.x;
    if (j >= pc.clusterCount) return;
    uint cj = clusterAt(j);
    if (clusters[cj].position.w < 0.5) return;
    vec3 sum = vec3(0.0);
    uint members = 0u;
    for (uint i = 0u; i < pc.count; ++i) {
        Vpl v = vpls[vplAt(i)];
        if (int(v.normal.w) != int(cj)) continue;
        sum += v.flux.rgb;
        ++members;
    }
    clusters[cj].flux = vec4(sum, 0.0);
    clusters[cj].normal.w = float(members);
}
