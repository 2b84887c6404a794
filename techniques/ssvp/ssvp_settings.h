#pragma once
/**
 * Parameters of `ssvp` (screen-space VPL propagation, Aranha, Macedo & Apolinario; notes 002)
 * and their parsed form. Defaults are the paper's where it gives them; every other choice is in
 * techniques/ssvp/README.md.
 */
#include <cstdint>
#include <vector>

#include "core/params/params.h"
#include "core/vpl/vpl_shading.h"

namespace gilab {

/** How second-bounce VPLs are shadowed (the paper does not say; issue 29). */
enum class SecondBounceVisibility {
    None,     // unshadowed: the method as read
    Cluster,  // the map of the nearest first-bounce cluster
    OwnMaps,  // ours: K-means over the second-bounce VPLs, one paraboloid map per cluster
};

struct SsvpSettings {
    // Buffers and maps (Rebuild).
    uint32_t firstBounceVpls = 256;   // N1 (§III-A)
    uint32_t secondBounceVpls = 256;  // N2 (§IV-A)
    uint32_t clusters = 8;            // C (§V: 8 recommended)
    uint32_t secondClusters = 32;     // C2, second_bounce_visibility = own_maps only (ours)
    uint32_t paraboloidResolution = 256;
    uint32_t rsmResolution = 512;
    uint32_t kmeansSeed = 1;
    // The technique's sampling pattern (techniques/ssvp/README.md "seed"): a Cranley-Patterson
    // shift of the first-bounce Hammersley VPLs and another K-means start; 0 = the unseeded
    // pattern, bit for bit.
    uint32_t seed = 0;
    int light = -1;  // scene light index of the main light; -1 = the first spot or directional
    // Per frame.
    int bounces = 2;
    float positionWeight = 0.6f;  // w1 (Eq. 2)
    float normalWeight = 0.4f;    // w2
    uint32_t kmeansIterations = 5;
    bool literalMetric = false;  // Eq. 2 as printed (sign-inverted normal term)
    uint32_t maxSubdivision = 4;
    float maxEdgeDeg = 15.0f;
    float centroidOffset = 0.001f;  // x scene diagonal
    bool eyeAtNearestVpl = false;   // map_eye = nearest_vpl
    uint32_t interleave = 4;
    InterleaveSubsets interleaveSubsets = InterleaveSubsets::Blocks;
    uint32_t blurRadius = 4;
    float clampDistance = 0.01f;  // x scene diagonal; 0 = no clamp
    float visibilityBiasTexels = 1.5f;
    bool paperWeights = false;
    SecondBounceVisibility secondVisibility = SecondBounceVisibility::None;
    bool reassignMembers = false;  // map_members = reassign (ours, issue 29)

    uint32_t perCluster() const { return clusters > 0 ? secondBounceVpls / clusters : 0; }
    /** Second-bounce VPLs in the frame (0 with bounces = 1). */
    uint32_t secondCount() const { return bounces >= 2 ? secondBounceVpls : 0u; }
    /** Clusters of the second-bounce VPLs with their own maps (0 unless own_maps). */
    uint32_t ownMapClusters() const {
        return secondVisibility == SecondBounceVisibility::OwnMaps && secondCount() > 0
                   ? secondClusters
                   : 0u;
    }
    /** Paraboloid map layers: C, plus C2 with own_maps. */
    uint32_t mapLayers() const { return clusters + ownMapClusters(); }
};

std::vector<ParamSpec> ssvpParamSpecs();
/** Parses and cross-checks (throws gilab::Error naming the parameter). */
SsvpSettings ssvpSettingsFrom(const ParamSet& params);

}  // namespace gilab
