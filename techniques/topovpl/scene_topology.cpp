#include "scene_topology.h"

#include "core/scene/scene.h"
#include "core/util/error.h"
#include "core/voxel/distance_transform.h"
#include "core/voxel/thinning.h"
#include "core/voxel/voxelizer.h"
#include "nearest_node.h"

namespace gilab::topo {

SceneTopology buildSceneTopology(vk::Context& ctx, const vk::GpuScene& gpuScene, const Scene& scene,
                                 const TopologySettings& s, const StepTimer& time) {
    if (!scene.caps.bounds.valid()) throw Error("topology: the scene has no geometry");
    SceneTopology t;
    t.grid = VoxelGrid(scene.caps.bounds, s.resolution);
    const uint32_t n = s.resolution;
    t.dims = {n, n, n};
    std::vector<uint8_t> solid(t.dims.count(), 0);
    time("voxelization", [&] {
        Voxelizer voxelizer(ctx, gpuScene, t.grid);
        voxelizer.run();
        const VoxelData data = voxelizer.readVoxels();
        for (size_t i = 0; i < solid.size(); ++i)
            solid[i] = data.count[i] > 0 ? 1 : 0;
        // Close the empty space a margin beyond the scene's bounds (and at the grid's border).
        const glm::ivec3 lo = t.grid.voxelOf(scene.caps.bounds.lo) - kBoundsMarginVoxels;
        const glm::ivec3 hi = t.grid.voxelOf(scene.caps.bounds.hi) + kBoundsMarginVoxels;
        const int last = int(n) - 1;
        for (uint32_t z = 0; z < n; ++z)
            for (uint32_t y = 0; y < n; ++y)
                for (uint32_t x = 0; x < n; ++x) {
                    const glm::ivec3 c(x, y, z);
                    if (glm::any(glm::lessThan(c, glm::max(lo, glm::ivec3(1)))) ||
                        glm::any(glm::greaterThan(c, glm::min(hi, glm::ivec3(last - 1)))))
                        solid[t.dims.index(x, y, z)] = 1;
                }
    });
    std::vector<float> radius;
    std::vector<uint32_t> chessboard, opening;
    time("distance_transform", [&] {
        if (s.ballMetric == BallMetric::Euclidean) radius = distanceTransform(solid, t.dims);
        if (s.ballMetric == BallMetric::Chessboard || s.skeletonFilter == SkeletonFilter::Lifespan)
            chessboard = chessboardDistanceTransform(solid, t.dims);
        if (s.ballMetric == BallMetric::Chessboard)
            radius.assign(chessboard.begin(), chessboard.end());
        if (s.skeletonFilter == SkeletonFilter::Lifespan)
            opening = chessboardOpening(chessboard, t.dims);
    });
    std::vector<uint8_t> empty(solid.size());
    for (size_t i = 0; i < empty.size(); ++i) {
        empty[i] = solid[i] ? 0 : 1;
        t.emptyVoxels += empty[i];
    }
    t.solidVoxels = uint32_t(solid.size()) - t.emptyVoxels;
    std::vector<uint8_t> skeleton = empty;
    time("thinning", [&] {
        ThinningOptions options;
        if (s.skeletonFilter == SkeletonFilter::Lifespan) {
            options.distance = &chessboard;
            options.opening = &opening;
        }
        t.anchoredVoxels = thinCurveSkeleton(skeleton, t.dims, options).anchored;
    });
    std::vector<glm::ivec3> voxels;
    std::vector<float> radii;
    for (uint32_t z = 0; z < n; ++z)
        for (uint32_t y = 0; y < n; ++y)
            for (uint32_t x = 0; x < n; ++x)
                if (skeleton[t.dims.index(x, y, z)]) {
                    voxels.emplace_back(x, y, z);
                    radii.push_back(radius[t.dims.index(x, y, z)]);
                }
    t.skeletonVoxels = uint32_t(voxels.size());
    time("segmentation", [&] {
        t.graph = buildSkeletonGraph(voxels, radii, s.skeletonFilter == SkeletonFilter::SpurPrune,
                                     s.ballMetric);
        t.segmentation = segmentSkeleton(t.graph, s.coverageSplit);
    });
    time("clustering", [&] {
        clusterSkeleton(t.graph, t.segmentation, s.alpha, empty, t.dims, s.mergeVisible,
                        s.gatePlacement, s.mergeVisibility, s.clusterRule);
    });
    time("nearest_node", [&] {
        const std::vector<uint32_t> labels =
            nearestNodeGrid(empty, t.dims, voxels, t.graph.voxelNode);
        t.voxelCluster.assign(labels.size(), kNoNode);
        for (size_t i = 0; i < labels.size(); ++i)
            if (labels[i] != kNoNode) t.voxelCluster[i] = t.segmentation.cluster[labels[i]];
    });
    // Gates in world units: voxel coordinates are voxel corners; centres are at + 0.5.
    const float v = t.grid.voxelSize();
    for (const Gate& g : t.segmentation.gates)
        t.gates.push_back({t.grid.gridToWorld(g.centre + 0.5f), g.normal, g.radius * v,
                           g.radiusA * v, g.radiusB * v, g.clusterA, g.clusterB, g.radiusNeck * v});
    return t;
}

}  // namespace gilab::topo
