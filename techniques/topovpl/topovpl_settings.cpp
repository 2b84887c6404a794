#include "topovpl_settings.h"

#include <string>

#include "core/util/error.h"

namespace gilab {
namespace {
constexpr ParamStage kRebuild = ParamStage::Rebuild;
}  // namespace

std::vector<ParamSpec> topovplParamSpecs() {
    return {
        intParam("voxel_resolution", 256, 32, 512, "voxels",
                 "binary voxel grid of the topology, per axis (paper 256)", kRebuild),
        floatParam("alpha", 20.0, 0.0, 100.0, "%",
                   "cluster radius tolerance, E3: |maxball - R_C| <= alpha R_C (paper 20)",
                   kRebuild),
        enumParam("cluster_merge", "visible", {"visible", "none"},
                  "visible: merge adjacent clusters whose kept nodes all see each other (ours) | "
                  "none: the paper's greedy clusters as printed",
                  kRebuild),
        floatParam("merge_visibility", 1.0, 0.0, 1.0, "",
                   "cluster_merge = visible: the share of ball-sample pairs of the union's kept "
                   "nodes that must see each other (1 = all)",
                   kRebuild),
        enumParam("gate_placement", "bottleneck", {"bottleneck", "midpoint"},
                  "bottleneck: a gate at the narrowest node of its skeleton line, the doorway "
                  "(ours) | midpoint: at the segmented edge's midpoint (E4 as printed)",
                  kRebuild),
        enumParam("cluster_rule", "chained", {"chained", "seed"},
                  "E3's radius test: chained: |maxball(nb) - maxball(m)| <= alpha R_C, within "
                  "alpha of the member that reaches it (default) | seed: |maxball(nb) - R_C| "
                  "<= alpha R_C, every member within alpha of the cluster's largest ball",
                  kRebuild),
        enumParam("ball_metric", "euclidean", {"euclidean", "chessboard"},
                  "maximal balls (radii, E2 coverage, E3 ball traversal, spur pruning): "
                  "euclidean | chessboard: L-infinity cubes, as the authors' public code",
                  kRebuild),
        enumParam("coverage_split", "first", {"first", "most"},
                  "E2: split a line at its first uncovered node from L1 | at the most uncovered "
                  "one",
                  kRebuild),
        enumParam("skeleton_filter", "lifespan", {"lifespan", "spur_prune"},
                  "lifespan: the authors' thinning filter, keep a curve voxel iff its lifespan "
                  "exceeds opening - distance (chessboard; default) | spur_prune: prune end "
                  "branches inside their junction's ball (ours, the default before issue 30)",
                  kRebuild),
        enumParam("topology_cache", "on", {"on", "off"},
                  "reuse the precomputed topology from results/cache/topology ($GILAB_CACHE)",
                  kRebuild),
        addCrossRule("at most rsm_resolution^2",
                     intParam("vpls", 1024, 1, 65536, "",
                              "VPLs from the reflective shadow map (paper 512, 1024, 2048; 4192 "
                              "Sibenik)",
                              kRebuild)),
        intParam("seed", 0, 0, 1000000000, "",
                 "VPL pattern: Cranley-Patterson shift of the Hammersley points the VPLs read "
                 "the RSM at (an offset hashed from the seed); 0 = the unshifted points (the "
                 "images from before the parameter)",
                 kRebuild),
        intParam("rsm_resolution", 512, 16, 4096, "texels",
                 "reflective shadow map side (the paper does not say how it makes VPLs)", kRebuild),
        intParam("light", -1, -1, 1024, "",
                 "scene light index the VPLs come from (-1 = the first spot or directional)",
                 kRebuild),
        intParam("list_capacity_mib", 64, 1, 4096, "MiB",
                 "light-assignment entry buffer (8 bytes an entry); overflow is counted and "
                 "reported",
                 kRebuild),
        requirePowerOfTwo(intParam("tile_size", 32, 8, 32, "pixels",
                                   "clustered-shading tile side: 8, 16 or 32, one power-of-two "
                                   "tile in shared memory (not given; Olsson et al. 32)")),
        intParam("depth_slices", 16, 1, 64, "", "exponential depth slices (not given)"),
        floatParam("clamp_distance", 0.01, 0.0, 1.0, "scene diagonals",
                   "near-VPL clamp: 1/d^2 uses max(d, this); 0 = no clamp (the paper has none)"),
        enumParam("visibility", "gates", {"gates", "same_cluster", "none"},
                  "gates: same cluster or through a gate (E6, the method) | same_cluster: no "
                  "gate lighting (the paper's faster option) | none: every VPL unshadowed "
                  "(Table II's 'no shadows on indirect')"),
        enumParam("gate_target", "any", {"any", "far_cluster"},
                  "any: a gate's cone lights every cluster it reaches (the paper as printed) | "
                  "far_cluster: only the cluster on the gate's other side"),
        enumParam("gate_radius", "neck", {"neck", "min", "mean", "max"},
                  "gate disk radius: neck = the smallest maxball on its line (the doorway's "
                  "half-width; ours) | min, mean, max of the maxballs of the edge's two ends "
                  "(paper: min)"),
        floatParam("gate_radius_scale", 1.0, 0.0, 100.0, "",
                   "multiplies the gate radius (> 1: oversized disks, §VI-B)"),
        enumParam("same_cluster_stat", "off", {"on", "off"},
                  "diagnostic pass diag.same_cluster_share: the share of the unshadowed VPL light "
                  "that same-cluster pairs carry (off by default: it runs in the frame's "
                  "submission, so the frame's wall time would hold it)"),
    };
}

TopovplSettings topovplSettingsFrom(const ParamSet& p) {
    TopovplSettings s;
    s.voxelResolution = uint32_t(p.getInt("voxel_resolution"));
    s.alphaPercent = float(p.getFloat("alpha"));
    s.mergeVisible = p.getEnum("cluster_merge") == "visible";
    s.gateAtBottleneck = p.getEnum("gate_placement") == "bottleneck";
    s.mergeVisibility = float(p.getFloat("merge_visibility"));
    s.chainedClusters = p.getEnum("cluster_rule") == "chained";
    s.chessboardBalls = p.getEnum("ball_metric") == "chessboard";
    s.splitMostUncovered = p.getEnum("coverage_split") == "most";
    s.lifespanFilter = p.getEnum("skeleton_filter") == "lifespan";
    s.useCache = p.getEnum("topology_cache") == "on";
    s.vpls = uint32_t(p.getInt("vpls"));
    s.seed = uint32_t(p.getInt("seed"));
    s.rsmResolution = uint32_t(p.getInt("rsm_resolution"));
    s.light = int(p.getInt("light"));
    s.listCapacityMiB = uint32_t(p.getInt("list_capacity_mib"));
    s.tileSize = uint32_t(p.getInt("tile_size"));
    s.depthSlices = uint32_t(p.getInt("depth_slices"));
    s.clampDistance = float(p.getFloat("clamp_distance"));
    const std::string vis = p.getEnum("visibility");
    s.visibility = vis == "gates"          ? TopoVisibility::Gates
                   : vis == "same_cluster" ? TopoVisibility::SameClusterOnly
                                           : TopoVisibility::Unshadowed;
    s.farClusterOnly = p.getEnum("gate_target") == "far_cluster";
    const std::string rule = p.getEnum("gate_radius");
    s.gateRadius = rule == "neck"   ? GateRadiusRule::Neck
                   : rule == "min"  ? GateRadiusRule::Min
                   : rule == "mean" ? GateRadiusRule::Mean
                                    : GateRadiusRule::Max;
    s.gateRadiusScale = float(p.getFloat("gate_radius_scale"));
    s.sameClusterStat = p.getEnum("same_cluster_stat") == "on";
    if (uint64_t(s.rsmResolution) * s.rsmResolution < s.vpls)
        throw Error("topovpl: vpls = " + std::to_string(s.vpls) + " exceeds the " +
                    std::to_string(s.rsmResolution) + "^2 texels of rsm_resolution");
    return s;
}

}  // namespace gilab
