#pragma once
/**
 * The precomputed topology of a scene's empty space (Noël & Biri 2014 §IV; notes 004 §2.A):
 *   voxelization   binary conservative voxelization (the shared GPU Voxelizer), N^3
 *   distance       exact Euclidean distance of every voxel to the nearest solid voxel (the
 *                  maximal-ball radii; core/voxel/distance_transform.h)
 *   thinning       curve skeleton of the empty voxels (core/voxel/thinning.h)
 *   segmentation   skeleton graph, topology / curvature / coverage nodes (skeleton_graph.h)
 *   clustering     visibility clusters (alpha) and gates
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
};

struct WorldGate {
    glm::vec3 centre{0.0f}, normal{0.0f};
    float radius = 0.0f;
    uint32_t clusterA = 0, clusterB = 0;
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
