#version 460
#extension GL_GOOGLE_include_directive : require
// K-means assignment step (§III-B): each valid VPL joins the seeded cluster with the smallest
// Eq. 2 distance (ties: the lower index); its cluster is its visibility map layer (normal.w).
// Changes are counted with an atomic for the convergence test.
#include "ssvp/kmeans_common.glsl"

layout(local_size_x = 64) in;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= pc.count || state.converged != 0u) return;
    int old = int(vpls[i].normal.w);
    int best = -1;
    if (vplValid(i)) {
        float bestDistance = 3.0e38;
        for (uint j = 0u; j < pc.clusterCount; ++j) {
            if (!clusterSeeded(j)) continue;
            float d = kmeansDistance(vpls[i].position.xyz, vpls[i].normal.xyz, clusters[j].mean.xyz,
                                     clusters[j].normal.xyz);
            if (d < bestDistance) {
                bestDistance = d;
                best = int(j);
            }
        }
    }
    if (best != old) atomicAdd(state.changed, 1u);
    vpls[i].normal.w = float(best);
}
