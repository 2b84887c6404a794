// The scene topology of the topological VPL technique (Noël & Biri 2014; techniques/topovpl/
// scene_topology.h) on real scenes: GPU voxelization, then the CPU skeleton pipeline.
#include <chrono>
#include <cstdio>
#include <string>

#include <gtest/gtest.h>

#include <tiny_gltf.h>

#include "tests/gpu_test_fixture.h"
#include "tests/temp_dir.h"

#include "core/gpu/gpu_scene.h"
#include "core/scene/procedural_cornell.h"
#include "core/scene/scene.h"
#include "techniques/topovpl/nearest_node.h"
#include "techniques/topovpl/scene_topology.h"
#include "techniques/topovpl/topology_export.h"

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

    // The debug export is a glTF file a viewer (here tinygltf) loads back: the skeleton's edges
    // as lines, the kept nodes as points, every gate as a 24-triangle disk.
    test::TempDir dir("gilab_topology");
    const std::string file = dir.path("cornell_topology.gltf");
    topo::exportTopologyGltf(t, file);
    tinygltf::Model model;
    tinygltf::TinyGLTF loader;
    std::string err, warn;
    ASSERT_TRUE(loader.LoadASCIIFromFile(&model, &err, &warn, file)) << err;
    size_t edges = 0;
    for (uint32_t a : t.segmentation.kept)
        for (uint32_t b : t.segmentation.segmentedAdjacency[a])
            edges += b > a;
    for (const tinygltf::Mesh& m : model.meshes) {
        const tinygltf::Primitive& p = m.primitives.at(0);
        const size_t vertices = model.accessors.at(size_t(p.attributes.at("POSITION"))).count;
        if (m.name == "skeleton") {
            EXPECT_EQ(p.mode, TINYGLTF_MODE_LINE);
            EXPECT_EQ(model.accessors.at(size_t(p.indices)).count, 2 * edges);
        } else if (m.name == "nodes") {
            EXPECT_EQ(vertices, t.segmentation.kept.size());
        } else if (m.name == "gates") {
            EXPECT_EQ(model.accessors.at(size_t(p.indices)).count, 72 * t.gates.size());
        }
    }
    EXPECT_EQ(model.meshes.size(), t.gates.empty() ? 2u : 3u);
}

}  // namespace
}  // namespace gilab
