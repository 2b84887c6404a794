#pragma once
/**
 * Parameters of `topovpl` (topological visibility-gate VPLs, Noël & Biri 2014; notes 004) and
 * their parsed form. Defaults are the paper's where it gives them (256^3 grid, alpha 20 %, gate
 * radius min of the two balls); every other choice is in techniques/topovpl/README.md.
 */
#include <cstdint>
#include <vector>

#include "core/params/params.h"

namespace gilab {

enum class TopoVisibility { Gates, SameClusterOnly, Unshadowed };
enum class GateRadiusRule { Min, Mean, Max, Neck };

struct TopovplSettings {
    // Set-up (Rebuild): the topology and the buffers.
    uint32_t voxelResolution = 256;   // §VI-A
    float alphaPercent = 20.0f;       // E3, §IV-B-2
    bool mergeVisible = true;         // our merge of mutually visible clusters (docs)
    bool gateAtBottleneck = true;     // ours; false: E4's edge midpoint
    float mergeVisibility = 1.0f;     // share of mutually visible ball samples to merge
    bool chainedClusters = true;      // E3: |r_nb - r_m| <= alpha R_C; false: |r_nb - R_C|
    bool chessboardBalls = false;     // maximal balls in L-infinity (cubes); false: Euclidean
    bool splitMostUncovered = false;  // E2: split at the most uncovered node; false: the first
    bool lifespanFilter = true;       // the authors' thinning filter; false: our spur pruning
    bool useCache = true;
    uint32_t vpls = 1024;  // Table I: 512, 1024, 2048
    // The VPL pattern (techniques/topovpl/README.md "seed"): a Cranley-Patterson shift of the
    // Hammersley points the VPLs read the RSM at; 0 = the unshifted points, bit for bit.
    uint32_t seed = 0;
    uint32_t rsmResolution = 512;
    int light = -1;
    uint32_t listCapacityMiB = 64;
    // Per frame.
    uint32_t tileSize = 32;       // clustered shading tile, pixels (not given; Olsson et al. 32)
    uint32_t depthSlices = 16;    // exponential depth slices (not given)
    float clampDistance = 0.01f;  // x scene diagonal; 0 = no clamp (the paper has none)
    TopoVisibility visibility = TopoVisibility::Gates;
    bool farClusterOnly = false;
    GateRadiusRule gateRadius = GateRadiusRule::Neck;
    float gateRadiusScale = 1.0f;
    bool sameClusterStat = true;  // diagnostic pass: same-cluster share of the unshadowed light
};

std::vector<ParamSpec> topovplParamSpecs();
/** Parses and cross-checks (throws gilab::Error naming the parameter). */
TopovplSettings topovplSettingsFrom(const ParamSet& params);

}  // namespace gilab
