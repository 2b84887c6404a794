#version 460
#extension GL_GOOGLE_include_directive : require
// K-means assignment step (§III-B): each valid VPL joins the seeded cluster with the smallest
// Eq. 2 distance (ties: the lower index); its cluster is its visibility map layer (normal.w).
// Changes are counted with an atomic for the convergence test.
#include "kmeans_common.glsl"

layout(local_size_x = 64) in;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= pc.count || state.converged != 0u) return;
    uint vi = vplAt(i);
    int old = int(vpls[vi].normal.w);
    int best = -1;
    if (vplValid(i)) {
        float bestDistance = 3.0e38;
        for (uint j = 0u; j < pc.clusterCount; ++j) {
            if (!clusterSeeded(j)) continue;
            uint cj = clusterAt(j);
            float d = kmeansDistance(vpls[vi].position.xyz, vpls[vi].normal.xyz,
                                     clusters[cj].mean.xyz, clusters[cj].normal.xyz);
            if (d < bestDistance) {
                bestDistance = d;
                best = int(cj);
            }
        }
    }
    if (best != old) atomicAdd(state.changed, 1u);
    vpls[vi].normal.w = float(best);
}
