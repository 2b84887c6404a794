// K-means over a range of VPLs (techniques/ssvp/ssvp_propagation.h; Aranha et al. §III-B): the
// first-bounce VPLs into clusters [0, C), or, with second_bounce_visibility = own_maps (ours), the
// second-bounce VPLs into clusters [C, C + C2). A VPL's normal.w holds its cluster's global index
// (= its paraboloid map layer). Bindings and push constants shared by kmeans_seed/assign/update,
// map_members, cluster_flux and second_bounce.comp.
#ifndef GILAB_SSVP_KMEANS_GLSL
#define GILAB_SSVP_KMEANS_GLSL
#include "common/vpl.glsl"

layout(set = 0, binding = 0, std430) buffer Vpls { Vpl vpls[]; };
layout(set = 0, binding = 1, std430) buffer Clusters { VplCluster clusters[]; };
layout(set = 0, binding = 2, std430) buffer KmeansState {
    uint changed;     // assignments changed by the last assign pass
    uint iterations;  // update passes run this frame
    uint converged;   // 1: no assignment changed, the remaining passes return at once
    uint seeded;      // 1: the clusters hold a warm start from an earlier frame
    uint reseeded;    // empty clusters re-seeded this frame
    uint activeClusters;  // clusters with members after the last update (= maps rendered)
    uint assigned;    // VPLs in those clusters (the valid first-bounce VPLs)
    uint pad0;
} state;

layout(push_constant, std430) uniform KmeansPush {
    float positionWeight;  // w1 (Eq. 2)
    float normalWeight;    // w2
    float invDiagonal;     // positions are compared in units of the scene diagonal
    float eyeOffset;       // map eye = centroid + offset x normal (world units)
    uint count;            // VPLs clustered (from vplBase)
    uint clusterCount;     // clusters (from clusterBase)
    uint iteration;        // this pass's iteration (0-based)
    uint metric;           // 0 corrected: w2 (1 - (n_i.n_j)+); 1 literal: w2 (n_i.n_j)+
    uint seed;             // first-frame seeding
    uint secondCount;      // second-bounce VPLs (second_bounce.comp; first-bounce range only)
    uint perCluster;       // second-bounce VPLs per cluster M = N2 / C
    uint paperWeights;     // 1: Eq. 6's constant phi (weights = paper)
    uint secondVisibility; // 1: second-bounce VPLs take the nearest first-bounce cluster's map
    uint mapResolution;
    uint eyeAtVpl;         // 1: the map's eye is the member VPL nearest the centroid
    uint reassign;         // 1: members their map does not see move to a map that does
    float biasTexels;      // visibility tolerance in map texels (the gather's)
    uint vplBase;          // first VPL of the clustered range (0, or N1 for the second bounce)
    uint clusterBase;      // first cluster of the range (0, or C for the second bounce)
} pc;

// Global indices of the range's VPL i and cluster j.
uint vplAt(uint i) { return pc.vplBase + i; }
uint clusterAt(uint j) { return pc.clusterBase + j; }

// Eq. 2 with the position term over the scene diagonal (notes 002 §9). As printed the normal
// term rewards dissimilar normals; the corrected form uses the dissimilarity 1 - (n_i.n_j)+.
float kmeansDistance(vec3 p, vec3 n, vec3 center, vec3 centerNormal) {
    float cosine = max(dot(n, centerNormal), 0.0);
    float normalTerm = pc.metric == 1u ? cosine : 1.0 - cosine;
    return pc.positionWeight * length(p - center) * pc.invDiagonal +
           pc.normalWeight * normalTerm;
}

bool vplValid(uint i) { return vpls[vplAt(i)].position.w > 0.5; }
bool clusterSeeded(uint j) { return clusters[clusterAt(j)].mean.w > 0.5; }

#endif  // GILAB_SSVP_KMEANS_GLSL
