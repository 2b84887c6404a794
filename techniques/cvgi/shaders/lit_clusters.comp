#version 460
#extension GL_GOOGLE_include_directive : require
// Emitter update, step 2b (§4.4): each cluster pulls its lit voxels' radiosity (the paper adds it
// with atomicAdd from the voxels; pulling over the cluster's voxel list gives the same sum without
// atomics), counts them and takes their centroid weighted by radiosity (the light's centre; the
// paper does not say how its form factor places it). A cluster is lit when the count is > 0.
#include "cvgi_common.glsl"

layout(local_size_x = 64) in;

void main() {
    uint c = gl_GlobalInvocationID.x;
    if (c >= u.counts.y) return;
    CvgiCluster cl = clusters[c];
    vec3 sum = vec3(0.0), sumCentre = vec3(0.0);
    float weights = 0.0;
    uint lit = 0u;
    for (int k = 0; k < cl.aabbMax.w; ++k) {
        uint v = clusterVoxels[cl.aabbMin.w + k];
        vec4 l = voxelLight[v];
        if (l.w <= 0.0) continue;
        sum += l.rgb;
        float w = l.r + l.g + l.b;
        sumCentre += w * (vec3(cvgiCoord(v)) + 0.5);
        weights += w;
        ++lit;
    }
    if (lit > 0u) atomicAdd(counters[CVGI_COUNT_LIT], lit);
    clusterLight[c].radiosity = vec4(sum, float(lit));
    clusterLight[c].litCentroid = vec4(weights > 0.0 ? sumCentre / weights : vec3(0.0), 0.0);
}
