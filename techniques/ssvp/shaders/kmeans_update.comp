#version 460
#extension GL_GOOGLE_include_directive : require
// K-means update step (§III-B), one workgroup, thread j = cluster j (C <= 64). Every pass is its
// own dispatch after the assignment's, so the sums never race (the authors' code resets its
// counters behind a workgroup barrier only). Per cluster, from the current assignment:
//   members > 0: centroid = mean position, normal = normalised mean normal (a mean shorter than
//                1e-3, opposing normals, keeps the previous normal), flux = sum, map active;
//                the map's eye is the centroid (or, map_eye = nearest_vpl, the member nearest
//                to it), moved eyeOffset along the normal
//   members = 0: re-seeded at the farthest valid VPL not taken yet (largest Eq. 2 distance to
//                its own centroid), so no centroid is ever (0,0,0) or NaN; no map this pass
// Convergence (a later pass with no changed assignment) makes the rest of the frame's passes
// return at once.
#include "kmeans_common.glsl"

layout(local_size_x = 64) in;

shared uint sMembers[64];
shared uint sTaken[64];

void main() {
    uint j = gl_LocalInvocationID.x;
    if (state.converged != 0u) return;
    if (pc.iteration > 0u && state.changed == 0u) {
        if (j == 0u) state.converged = 1u;
        return;
    }
    uint cj = clusterAt(j);
    vec3 sumP = vec3(0.0), sumN = vec3(0.0), sumF = vec3(0.0);
    uint members = 0u;
    if (j < pc.clusterCount) {
        for (uint i = 0u; i < pc.count; ++i) {
            Vpl v = vpls[vplAt(i)];
            if (int(v.normal.w) != int(cj)) continue;
            sumP += v.position.xyz;
            sumN += v.normal.xyz;
            sumF += v.flux.rgb;
            ++members;
        }
    }
    sMembers[j] = members;
    barrier();
    if (j < pc.clusterCount && members > 0u) {
        vec3 mean = sumP / float(members);
        float len = length(sumN);
        vec3 n = len > 1e-3 * float(members) ? sumN / len : clusters[cj].normal.xyz;
        if (!(dot(n, n) > 0.5)) n = vec3(0.0, 0.0, 1.0);
        clusters[cj].mean = vec4(mean, 1.0);
        clusters[cj].normal = vec4(n, float(members));
        vec3 eye = mean;
        vec3 eyeNormal = n;
        if (pc.eyeAtVpl != 0u) {
            // map_eye = nearest_vpl: the member closest to the mean (lowest index on ties), so
            // the eye is on a lit surface, never inside an object or floating (notes 002 §6).
            float best = 3.0e38;
            for (uint i = 0u; i < pc.count; ++i) {
                Vpl v = vpls[vplAt(i)];
                if (int(v.normal.w) != int(cj)) continue;
                float d = dot(v.position.xyz - mean, v.position.xyz - mean);
                if (d < best) {
                    best = d;
                    eye = v.position.xyz;
                    eyeNormal = v.normal.xyz;
                }
            }
        }
        clusters[cj].position = vec4(eye + pc.eyeOffset * eyeNormal, 1.0);
        clusters[cj].flux = vec4(sumF, 0.0);
    }
    barrier();
    if (j == 0u) {
        // Empty clusters, in index order: the farthest VPLs, distinct.
        uint taken = 0u, activeCount = 0u, assigned = 0u;
        for (uint c = 0u; c < pc.clusterCount; ++c) {
            activeCount += sMembers[c] > 0u ? 1u : 0u;
            assigned += sMembers[c];
        }
        state.activeClusters = activeCount;
        state.assigned = assigned;
        for (uint c = 0u; c < pc.clusterCount; ++c) {
            if (sMembers[c] > 0u) continue;
            uint cc = clusterAt(c);
            clusters[cc].position.w = 0.0;
            clusters[cc].normal.w = 0.0;
            clusters[cc].flux = vec4(0.0);
            int far = -1;
            float farDistance = -1.0;
            for (uint i = 0u; i < pc.count; ++i) {
                Vpl v = vpls[vplAt(i)];
                int own = int(v.normal.w);
                if (!vplValid(i) || own < 0) continue;
                bool used = false;
                for (uint k = 0u; k < taken; ++k)
                    used = used || sTaken[k] == i;
                if (used) continue;
                float d = kmeansDistance(v.position.xyz, v.normal.xyz, clusters[own].mean.xyz,
                                         clusters[own].normal.xyz);
                if (d > farDistance) {
                    farDistance = d;
                    far = int(i);
                }
            }
            if (far < 0) continue;  // no VPL left: stays unseeded or keeps its old centroid
            sTaken[taken++] = uint(far);
            Vpl f = vpls[vplAt(uint(far))];
            clusters[cc].mean = vec4(f.position.xyz, 1.0);
            clusters[cc].normal = vec4(f.normal.xyz, 0.0);
            clusters[cc].position = vec4(f.position.xyz, 0.0);
            state.reseeded += 1u;
        }
        state.iterations += 1u;
        state.changed = 0u;
    }
}
