#version 460
#extension GL_GOOGLE_include_directive : require
// Emitter update, step 3b, the light bounce (§4.4, Fig. 5 right): 64 threads per voxel face of
// each voxel in the gather list; each thread takes clusters k, k + 64, ... of the face's cached
// visible list (the paper: at most 2 per thread for 128 rays) and adds the lit ones with the
// face-to-cluster form factor. A cluster whose AABB is nearer than the threshold is gathered voxel
// by voxel instead (its lit voxels, each a source of area s^2 on its own axis face).
// E = sum B A cos cos / (pi r^2 + A) in grid units (irradiance, W/m^2; techniques/cvgi/README.md).
// gather = ray_weighted (ours, u.packing.y): the Monte Carlo estimate over the same rays instead,
// E = (2 pi / rays) sum over the hits of L cos = (2 / rays) sum_c Bmean_c W_c, with Bmean_c the
// cluster's radiosity summed over its lit voxels and divided by all its voxels (a ray meets any
// of them) and W_c the cosine sum of the face's rays that met the cluster's front (set-up).
#include "cvgi_common.glsl"

layout(local_size_x = 64) in;

shared vec3 partial[64];

vec3 gatherCluster(uint c, uint entry, vec3 x, vec3 n) {
    CvgiClusterLight light = clusterLight[c];
    if (light.radiosity.w <= 0.0) return vec3(0.0);  // not lit
    CvgiCluster cl = clusters[c];
    if (u.packing.y != 0u) {
        float meanRadiosityScale = 1.0 / float(max(cl.aabbMax.w, 1));
        return light.radiosity.rgb * (meanRadiosityScale * 2.0 * faceWeights[entry] /
                                      float(max(u.packing.z, 1u)));
    }
    vec3 lo = vec3(cl.aabbMin.xyz), hi = vec3(cl.aabbMax.xyz) + 1.0;
    vec3 outside = max(max(lo - x, x - hi), vec3(0.0));
    if (length(outside) >= u.biases.z) {
        vec3 m = cl.normal.xyz;
        vec3 y = light.litCentroid.xyz + 0.5 * m;  // the lit voxels' surface, half a voxel out
        // mean lit radiosity x F(face -> disk of the lit area, n_lit voxels)
        float area = light.radiosity.w;
        return light.radiosity.rgb / area * cvgiDiskFormFactor(x, n, y, m, area);
    }
    vec3 e = vec3(0.0);
    for (int k = 0; k < cl.aabbMax.w; ++k) {
        uint v = clusterVoxels[cl.aabbMin.w + k];
        vec4 l = voxelLight[v];
        if (l.w <= 0.0) continue;
        vec3 m = vec3(cvgiAxisDir(cvgiAxis(v)));
        vec3 y = vec3(cvgiCoord(v)) + 0.5 + 0.5 * m;
        e += l.rgb * cvgiDiskFormFactor(x, n, y, m, 1.0);
    }
    return e;
}

void main() {
    uint lid = gl_LocalInvocationID.x;
    uint jobs = counters[CVGI_COUNT_GATHER] * 6u;
    for (uint job = gl_WorkGroupID.x; job < jobs; job += gl_NumWorkGroups.x) {
        uint v = gatherList[job / 6u], f = job % 6u;
        uint face = 6u * v + f;
        vec3 n = vec3(cvgiAxisDir(f));
        vec3 x = vec3(cvgiCoord(v)) + 0.5 + 0.5 * n;  // face centre
        uint first = faceOffset[face], count = faceOffset[face + 1u] - first;
        vec3 e = vec3(0.0);
        for (uint k = lid; k < count; k += 64u)
            e += gatherCluster(cvgiFaceCluster(first + k), first + k, x, n);
        partial[lid] = e;
        barrier();
        for (uint stride = 32u; stride > 0u; stride >>= 1u) {
            if (lid < stride) partial[lid] += partial[lid + stride];
            barrier();
        }
        if (lid == 0u) faceIrradiance[face] = vec4(partial[0], 1.0);
        barrier();
    }
}
