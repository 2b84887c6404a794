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
 * The grid's border layer is made solid, so the empty space is closed (a scene open to the sky
 * is closed by the grid's box). Positions and radii are converted to world units here.
 */
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "core/voxel/grid_dims.h"
#include "core/voxel/voxel_grid.h"
#include "techniques/topovpl/skeleton_graph.h"

namespace gilab {
namespace vk {
class Context;
class GpuScene;
}  // namespace vk
struct Scene;

namespace topo {

struct TopologySettings {
    uint32_t resolution = 256;  // voxels per axis (paper 256)
    float alpha = 0.2f;         // cluster radius tolerance (paper 20 %)
    bool mergeVisible = true;   // our visibility merge (cluster_merge.h); false: the paper's
                                // literal greedy clusters
    GatePlacement gatePlacement = GatePlacement::Bottleneck;  // ours; Midpoint: E4 as printed
    float mergeVisibility = 1.0f;  // share of visible ball-sample pairs a merge needs
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
    SkeletonGraph graph;  // voxel units
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
