// The scene topology of the topological VPL technique (Noël & Biri 2014; techniques/topovpl/
// scene_topology.h) on real scenes: GPU voxelization, then the CPU skeleton pipeline.
#include <chrono>
#include <cstdio>
#include <string>

#include <gtest/gtest.h>

#include "tests/gpu_test_fixture.h"

#include "core/gpu/gpu_scene.h"
#include "core/scene/procedural_cornell.h"
#include "core/scene/scene.h"
#include "techniques/topovpl/nearest_node.h"
#include "techniques/topovpl/scene_topology.h"

namespace gilab {
namespace {

using GpuTopology = test::ValidatedGpuTest;

topo::StepTimer printTimer() {
    return [](const std::string& name, const std::function<void()>& work) {
        const auto t0 = std::chrono::steady_clock::now();
        work();
        const double ms =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0)
                .count();
        std::printf("  %s: %.1f ms\n", name.c_str(), ms);
    };
}

// The Cornell box (closed but for its front, two boxes inside) at 64^3: a skeleton, clusters that
// cover every node, and every empty voxel that a skeleton voxel reaches gets a cluster.
TEST_F(GpuTopology, CornellBoxTopologyLabelsTheEmptySpace) {
    Scene scene = makeCornellBox(CornellBoxParams{});
    scene.computeCaps();
    vk::GpuScene gpuScene(*m_ctx, scene);
    topo::TopologySettings s;
    s.resolution = 64;
    const topo::SceneTopology t =
        topo::buildSceneTopology(*m_ctx, gpuScene, scene, s, printTimer());
    std::printf(
        "Cornell 64^3: %u empty, %u solid voxels, %u skeleton voxels, %zu nodes, %zu kept, "
        "%u clusters, %zu gates\n",
        t.emptyVoxels, t.solidVoxels, t.skeletonVoxels, t.graph.position.size(),
        t.segmentation.kept.size(), t.segmentation.clusterCount, t.gates.size());
    EXPECT_GT(t.skeletonVoxels, 0u);
    EXPECT_GE(t.segmentation.clusterCount, 1u);
    size_t labelled = 0;
    for (uint32_t c : t.voxelCluster) {
        if (c == topo::kNoNode) continue;
        ASSERT_LT(c, t.segmentation.clusterCount);
        ++labelled;
    }
    // The grid's border closes the box's open front, so all the empty space is one piece.
    EXPECT_EQ(labelled, size_t(t.emptyVoxels));
    for (const topo::WorldGate& g : t.gates) {
        EXPECT_GT(g.radius, 0.0f);
        EXPECT_NEAR(glm::length(g.normal), 1.0f, 1e-4f);
    }
}

}  // namespace
}  // namespace gilab
