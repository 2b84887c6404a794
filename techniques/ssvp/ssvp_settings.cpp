#include "ssvp_settings.h"

#include <string>

#include "core/util/error.h"

namespace gilab {
namespace {

constexpr ParamStage kRebuild = ParamStage::Rebuild;
constexpr double kMaxMapMiB = 4096.0;  // as the shared shadow cubes (core/technique)

}  // namespace

std::vector<ParamSpec> ssvpParamSpecs() {
    return {
        addCrossRule("at least clusters",
                     intParam("first_bounce_vpls", 256, 1, 4096, "",
                              "N1 first-bounce VPLs from the RSM, Hammersley pattern (paper 256)",
                              kRebuild)),
        addCrossRule("a multiple of clusters",
                     intParam("second_bounce_vpls", 256, 0, 8192, "",
                              "N2 second-bounce VPLs in all, N2 / C per cluster (paper 64, 256, "
                              "1024)",
                              kRebuild)),
        intParam("clusters", 8, 1, 64, "",
                 "C K-means clusters = paraboloid maps (paper 4, 8, 16, 32; 8 recommended)",
                 kRebuild),
        addCrossRule("maps x side^2 x 36 bytes <= 4096 MiB",
                     intParam("paraboloid_resolution", 256, 16, 2048, "texels",
                              "paraboloid map side (paper 256; authors' code 1024)", kRebuild)),
        intParam("rsm_resolution", 512, 16, 4096, "texels",
                 "reflective shadow map side (not given; authors' code 2048)", kRebuild),
        intParam("kmeans_seed", 1, 0, 1000000000, "",
                 "seed of the first frame's random centroid VPLs", kRebuild),
        intParam("seed", 0, 0, 1000000000, "",
                 "sampling pattern: Cranley-Patterson shift of the first-bounce Hammersley VPLs "
                 "(an offset hashed from the seed) and K-means seed kmeans_seed + seed x "
                 "0x9E3779B9; 0 = the unshifted pattern (the images from before the parameter)",
                 kRebuild),
        intParam("light", -1, -1, 1024, "",
                 "scene light index of the main light (-1 = the first spot or directional)",
                 kRebuild),
        intParam("bounces", 2, 1, 2, "", "indirect bounces: 1 = first-bounce VPLs only, 2 = both"),
        floatParam("kmeans_position_weight", 0.6, 0.0, 100.0, "",
                   "w1 of Eq. 2, on distances in scene diagonals (paper 0.6; code 1.0)"),
        floatParam("kmeans_normal_weight", 0.4, 0.0, 100.0, "",
                   "w2 of Eq. 2 (paper 0.4; code 0.2)"),
        intParam("kmeans_iterations", 5, 1, 64, "",
                 "K-means iterations at most per frame; stops early on convergence (paper <= 5)"),
        enumParam("kmeans_metric", "corrected", {"corrected", "literal"},
                  "Eq. 2 normal term: corrected w2 (1 - (n.n)+) | literal w2 (n.n)+ as printed "
                  "(sign-inverted)"),
        intParam("paraboloid_max_subdivision", 4, 1, 4, "",
                 "most splits per triangle edge in the paraboloid geometry shader (1 = none)"),
        floatParam("paraboloid_max_edge_deg", 15.0, 1.0, 180.0, "deg",
                   "split triangles until each edge subtends at most this from the eye"),
        floatParam("centroid_offset", 0.001, 0.0, 0.1, "scene diagonals",
                   "paraboloid eye = centroid + offset x cluster normal (not given in the paper; "
                   "techniques/ssvp/README.md)"),
        enumParam("map_eye", "centroid", {"centroid", "nearest_vpl"},
                  "paraboloid map eye: the cluster centroid (paper) | the member VPL nearest "
                  "to it (never inside geometry or in the air)"),
        intParam("interleave", 4, 1, 16, "pixels",
                 "interleaved shading pattern I x I (paper 4; authors' code 2)"),
        enumParam("interleave_subsets", "blocks", {"blocks", "fold", "modulo"},
                  "which VPLs each sub-image gets: blocks (runs of L consecutive VPLs, an L x "
                  "n/(L I^2) grid of the RSM each) | fold (xor of index chunks: every RSM box of "
                  "I^2 VPLs gives one to each) | modulo (VPL k mod I^2: one strip of the RSM "
                  "each, the version before issue 29)"),
        intParam("blur_radius", 4, 0, 16, "pixels",
                 "edge-aware Gaussian radius, sigma = radius / 2 (0 = no blur; not given)"),
        floatParam("clamp_distance", 0.01, 0.0, 1.0, "scene diagonals",
                   "near-VPL clamp: 1/d^2 uses max(d, this); 0 = no clamp (the paper has none)"),
        floatParam("visibility_bias_texels", 1.5, 0.0, 1000.0, "texels",
                   "paraboloid visibility tolerance, in map texels at the receiver"),
        enumParam("weights", "physical", {"physical", "paper"},
                  "physical: flux per VPL from its sampling density, 1/N per bounce | paper: "
                  "Eq. 6 equal weights over N1 + N2 (not energy-consistent)"),
        enumParam("map_members", "keep", {"keep", "reassign"},
                  "first-bounce VPLs their cluster's map does not see: keep (the paper) | "
                  "reassign to the nearest map that sees them, cluster fluxes re-summed (ours)"),
        enumParam("second_bounce_visibility", "none", {"none", "cluster", "own_maps"},
                  "second-bounce VPLs: none (unshadowed, the paper as read) | cluster (the map of "
                  "the nearest first-bounce cluster) | own_maps (ours: K-means over the "
                  "second-bounce VPLs, one paraboloid map per cluster, Dong et al.'s clustered "
                  "visibility as for the first bounce)"),
        addCrossRule("at most second_bounce_vpls (with own_maps)",
                     intParam("second_bounce_clusters", 32, 1, 64, "",
                              "C2 clusters and maps of the second-bounce VPLs "
                              "(second_bounce_visibility = own_maps only; ours; 32 keeps "
                              "0.86-1.05 of the exact second bounce on Sponza and the Cornell "
                              "box, 8 only 0.58 on Sponza)",
                              kRebuild)),
    };
}

SsvpSettings ssvpSettingsFrom(const ParamSet& p) {
    SsvpSettings s;
    s.firstBounceVpls = uint32_t(p.getInt("first_bounce_vpls"));
    s.secondBounceVpls = uint32_t(p.getInt("second_bounce_vpls"));
    s.clusters = uint32_t(p.getInt("clusters"));
    s.paraboloidResolution = uint32_t(p.getInt("paraboloid_resolution"));
    s.rsmResolution = uint32_t(p.getInt("rsm_resolution"));
    s.kmeansSeed = uint32_t(p.getInt("kmeans_seed"));
    s.seed = uint32_t(p.getInt("seed"));
    s.light = int(p.getInt("light"));
    s.bounces = int(p.getInt("bounces"));
    s.positionWeight = float(p.getFloat("kmeans_position_weight"));
    s.normalWeight = float(p.getFloat("kmeans_normal_weight"));
    s.kmeansIterations = uint32_t(p.getInt("kmeans_iterations"));
    s.literalMetric = p.getEnum("kmeans_metric") == "literal";
    s.maxSubdivision = uint32_t(p.getInt("paraboloid_max_subdivision"));
    s.maxEdgeDeg = float(p.getFloat("paraboloid_max_edge_deg"));
    s.centroidOffset = float(p.getFloat("centroid_offset"));
    s.eyeAtNearestVpl = p.getEnum("map_eye") == "nearest_vpl";
    s.interleave = uint32_t(p.getInt("interleave"));
    s.interleaveSubsets = interleaveSubsetsFrom(p.getEnum("interleave_subsets"));
    s.blurRadius = uint32_t(p.getInt("blur_radius"));
    s.clampDistance = float(p.getFloat("clamp_distance"));
    s.visibilityBiasTexels = float(p.getFloat("visibility_bias_texels"));
    s.paperWeights = p.getEnum("weights") == "paper";
    const std::string visibility = p.getEnum("second_bounce_visibility");
    s.secondVisibility = visibility == "cluster"    ? SecondBounceVisibility::Cluster
                         : visibility == "own_maps" ? SecondBounceVisibility::OwnMaps
                                                    : SecondBounceVisibility::None;
    s.secondClusters = uint32_t(p.getInt("second_bounce_clusters"));
    s.reassignMembers = p.getEnum("map_members") == "reassign";
    if (s.secondBounceVpls % s.clusters != 0) {
        throw Error("ssvp: second_bounce_vpls = " + std::to_string(s.secondBounceVpls) +
                    " must be a multiple of clusters = " + std::to_string(s.clusters) +
                    " (N2 / C second-bounce VPLs per cluster, Fig. 5)");
    }
    if (s.firstBounceVpls < s.clusters) {
        throw Error("ssvp: first_bounce_vpls = " + std::to_string(s.firstBounceVpls) +
                    " is below clusters = " + std::to_string(s.clusters) +
                    ": K-means needs at least one VPL per cluster");
    }
    if (s.ownMapClusters() > s.secondBounceVpls) {
        throw Error("ssvp: second_bounce_clusters = " + std::to_string(s.secondClusters) +
                    " is above second_bounce_vpls = " + std::to_string(s.secondBounceVpls) +
                    ": K-means needs at least one VPL per cluster");
    }
    // The maps: position RGBA32F + normal, albedo RGBA16F + D32 per texel and layer.
    const double mapMiB = double(s.mapLayers()) * s.paraboloidResolution * s.paraboloidResolution *
                          36.0 / (1024.0 * 1024.0);
    if (mapMiB > kMaxMapMiB) {
        throw Error("ssvp: " + std::to_string(s.mapLayers()) +
                    " paraboloid maps (clusters + second_bounce_clusters with own_maps) x "
                    "paraboloid_resolution = " +
                    std::to_string(s.paraboloidResolution) + "^2 needs " +
                    std::to_string(int(mapMiB)) + " MiB of paraboloid maps (limit " +
                    std::to_string(int(kMaxMapMiB)) + " MiB); lower one of them");
    }
    return s;
}

}  // namespace gilab
