#version 460
#extension GL_GOOGLE_include_directive : require
// Second-bounce VPLs (Aranha et al. §III-C, "projection-aware sampling"): M = N2 / C per active
// cluster, at the fixed Hammersley set of M points mapped to the unit disk (concentric map), the
// same for every cluster and frame. VPL k reads position, normal and albedo from its cluster's
// paraboloid map. Flux (techniques/ssvp/README.md "Weighting"):
//   physical  Phi_c x albedo x 4 (1 - r^2) / (1 + r^2)^3 / M   (cosine emission of the cluster
//             over the uniform-disk density; mean weight 1)
//   paper     Phi_c / members x albedo                          (Eq. 6's constant phi x colour)
// A texel with no surface, or a cluster with no map, gives an invalid VPL (kept in the count).
#include "kmeans_common.glsl"

layout(local_size_x = 64) in;

layout(set = 0, binding = 3, rgba32f) uniform readonly image2DArray mapPosition;
layout(set = 0, binding = 4, rgba16f) uniform readonly image2DArray mapNormal;
layout(set = 0, binding = 5, rgba16f) uniform readonly image2DArray mapAlbedo;

void main() {
    uint k = gl_GlobalInvocationID.x;
    if (k >= pc.secondCount) return;
    Vpl v;
    v.position = vec4(0.0);
    v.normal = vec4(0.0, 0.0, 1.0, -1.0);
    v.flux = vec4(0.0, 0.0, 0.0, 2.0);
    uint c = k / pc.perCluster;
    uint j = k % pc.perCluster;
    if (c < pc.clusterCount && clusters[c].position.w > 0.5) {
        vec2 disk = vplConcentricDisk(vplHammersley(j, pc.perCluster));
        float r = float(pc.mapResolution);
        ivec2 t = clamp(ivec2(vplParaboloidUv(disk) * r), ivec2(0), ivec2(int(r) - 1));
        vec4 p = imageLoad(mapPosition, ivec3(t, int(c)));
        if (p.w > 0.0) {
            vec3 albedo = imageLoad(mapAlbedo, ivec3(t, int(c))).rgb;
            vec3 phi = clusters[c].flux.rgb;
            vec3 flux = pc.paperWeights != 0u
                            ? phi / max(clusters[c].normal.w, 1.0) * albedo
                            : phi * albedo * vplDiskSampleWeight(disk) / float(pc.perCluster);
            vec3 n = normalize(imageLoad(mapNormal, ivec3(t, int(c))).xyz);
            bool ok = vplFinite(flux) && vplFinite(n) && max(flux.r, max(flux.g, flux.b)) > 0.0;
            if (ok) {
                v.position = vec4(p.xyz, 1.0);
                v.normal.xyz = n;
                v.flux.rgb = flux;
                if (pc.secondVisibility != 0u) {
                    int best = -1;
                    float bestDistance = 3.0e38;
                    for (uint q = 0u; q < pc.clusterCount; ++q) {
                        if (clusters[q].position.w < 0.5) continue;
                        float d = kmeansDistance(p.xyz, n, clusters[q].mean.xyz,
                                                 clusters[q].normal.xyz);
                        if (d < bestDistance) {
                            bestDistance = d;
                            best = int(q);
                        }
                    }
                    v.normal.w = float(best);
                }
            }
        }
    }
    vpls[pc.count + k] = v;
}
