#pragma once
/**
 * The precomputed topology of a scene's empty space (Noël & Biri 2014 §IV; notes 004 §2.A):
 *   voxelization   binary conservative voxelization (the shared GPU Voxelizer), N^3
 *   distance       exact Euclidean distance of every voxel to the nearest solid voxel (the
 *                  maximal-ball radii; core/voxel/distance_transform.h)
 *   thinning       curve skeleton of the empty voxels (core/voxel/thinning.h)
 *   segmentation   skeleton graph, topology / curvature (E1) / coverage (E2) nodes
 *                  (skeleton_graph.h)
 *   clustering     greedy visibility clusters (E3, alpha), our visibility merge of adjacent
 *                  mutually visible clusters (cluster_merge.h; settings.mergeVisible), gates (E4)
 *   nearest_node   nearest skeleton node of every empty voxel through the empty space, then
 *                  its cluster (nearest_node.h)
 * Every voxel outside the voxels that hold the scene's bounds is made solid (and the grid's
 * border layer), so the empty space is closed at the scene's box: a scene open to the sky is
 * lidded at its top, instead of keeping the cube grid's whole empty remainder, which wrapped the
 * scene and thinned into one clump node holding most of the skeleton (Sponza, as issue 30's review
 * measured it: 205,321 voxels, 64 % of the VPLs). A solid standing free in the empty space (not
 * touching the box or anything that does) still gets a closed surface of skeleton around it: the
 * setup warns when one node holds more than 1 % of the skeleton. Positions and radii are converted
 * to world units here.
 */
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "core/voxel/grid_dims.h"
#include "core/voxel/voxel_grid.h"
#include "skeleton_graph.h"

namespace gilab {
namespace vk {
class Context;
class GpuScene;
}  // namespace vk
struct Scene;

namespace topo {

/**
 * How the skeleton drops the branches that bumps of the shape grow:
 *   SpurPrune  ours: end branches whose tip lies in the maximal ball of their junction are
 *              pruned from the graph (skeleton_graph.h)
 *   Lifespan   the authors' thinning filter (Chaussard, Noël, Biri & Couprie 2013): a curve
 *              voxel is kept iff its lifespan (thinning passes since it became a curve) exceeds
 *              opening - distance, both chessboard (core/voxel/thinning.h)
 */
enum class SkeletonFilter : uint8_t { SpurPrune = 0, Lifespan = 1 };

/**
 * Voxels more than this many voxels outside the voxels that hold the scene's bounds are made
 * solid, so the empty space ends at the scene and not at the cube grid's border. 0, measured:
 * with a margin of 2 the empty layer wrapped the whole scene, and a solid surrounded by empty
 * space is a cavity of it, which a topology-preserving thinning must keep as a closed surface
 * (Sponza: one node of 145,000 voxels, 87 % of the skeleton). With 0 the scene's extreme
 * surfaces touch the closure, so the scene and the closure are one solid.
 */
inline constexpr int kBoundsMarginVoxels = 0;

struct TopologySettings {
    uint32_t resolution = 256;  // voxels per axis (paper 256)
    float alpha = 0.2f;         // cluster radius tolerance (paper 20 %)
    bool mergeVisible = true;   // our visibility merge (cluster_merge.h); false: the paper's
                                // literal greedy clusters
    GatePlacement gatePlacement = GatePlacement::Bottleneck;  // ours; Midpoint: E4 as printed
    float mergeVisibility = 1.0f;  // share of visible ball-sample pairs a merge needs
    ClusterRule clusterRule = ClusterRule::Chained;      // E3's reading (skeleton_graph.h)
    BallMetric ballMetric = BallMetric::Euclidean;       // maximal balls: radii and tests
    CoverageSplit coverageSplit = CoverageSplit::First;  // E2's split point
    SkeletonFilter skeletonFilter = SkeletonFilter::Lifespan;
};

struct WorldGate {
    glm::vec3 centre{0.0f}, normal{0.0f};
    float radius = 0.0f;                   // min(radiusA, radiusB)
    float radiusA = 0.0f, radiusB = 0.0f;  // maxball of the gate edge's ends a and b
    uint32_t clusterA = 0, clusterB = 0;
    float radiusNeck = 0.0f;  // the smallest maxball on the gate's line (<= radius)
};

struct SceneTopology {
    VoxelGrid grid;
    GridDims dims;
    uint32_t skeletonVoxels = 0, emptyVoxels = 0, solidVoxels = 0;
    uint64_t anchoredVoxels = 0;  // SkeletonFilter::Lifespan: voxels its rule kept
    SkeletonGraph graph;          // voxel units
    Segmentation segmentation;
    std::vector<uint32_t> voxelCluster;  // per voxel: cluster, kNoNode where solid / unreached
    std::vector<WorldGate> gates;        // world units
};

/** Times one named step (the caller's TechniqueContext::timeCpu, or a plain call). */
using StepTimer = std::function<void(const std::string&, const std::function<void()>&)>;

/** Builds the topology; `voxelize` runs on the GPU through the shared Voxelizer. */
SceneTopology buildSceneTopology(vk::Context& ctx, const vk::GpuScene& gpuScene, const Scene& scene,
                                 const TopologySettings& settings, const StepTimer& time);

}  // namespace topo
}  // namespace gilab
