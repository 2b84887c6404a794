#version 460
#extension GL_GOOGLE_include_directive : require
// First frame (or no warm start yet): "a random VPL is chosen as the centroid seed for each
// cluster" (§III-B). One thread; distinct valid VPLs drawn by a hash of (seed, cluster, try), so a
// fixed seed gives the same clusters. Clusters left without a seed (fewer valid VPLs than C) are
// seeded later from the farthest VPL (kmeans_update.comp).
#include "kmeans_common.glsl"

layout(local_size_x = 1) in;

#include "common/random.glsl"

void main() {
    if (state.seeded != 0u) return;
    uint valid = 0u;
    for (uint i = 0u; i < pc.count; ++i)
        if (vplValid(i)) ++valid;
    if (valid == 0u) return;  // nothing lit yet: try again next frame
    uint taken[64];
    for (uint j = 0u; j < pc.clusterCount; ++j) {
        uint cj = clusterAt(j);
        clusters[cj] = VplCluster(vec4(0.0), vec4(0.0, 0.0, 1.0, 0.0), vec4(0.0), vec4(0.0));
        if (j >= valid) continue;
        uint start = pcgHash(pc.seed * 9781u + j * 6271u + 1u) % pc.count;
        for (uint t = 0u; t < pc.count; ++t) {
            uint i = (start + t) % pc.count;
            if (!vplValid(i)) continue;
            bool used = false;
            for (uint k = 0u; k < j; ++k)
                used = used || taken[k] == i;
            if (used) continue;
            taken[j] = i;
            clusters[cj].mean = vec4(vpls[vplAt(i)].position.xyz, 1.0);
            clusters[cj].normal = vec4(vpls[vplAt(i)].normal.xyz, 0.0);
            break;
        }
    }
    state.seeded = 1u;
}
