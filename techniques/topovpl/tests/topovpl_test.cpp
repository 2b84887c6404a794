// The scene topology of the topological VPL technique (Noël & Biri 2014; techniques/topovpl/
// scene_topology.h) on real scenes: GPU voxelization, then the CPU skeleton pipeline.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <set>
#include <string>

#include <gtest/gtest.h>

#include <tiny_gltf.h>

#include "tests/gpu_test_fixture.h"
#include "tests/temp_dir.h"

#include "core/gpu/gpu_scene.h"
#include "core/passes/shared_passes.h"
#include "core/scene/procedural_cornell.h"
#include "core/scene/scene.h"
#include "core/scene/scene_loader.h"
#include "techniques/topovpl/nearest_node.h"
#include "techniques/topovpl/pixel_clusters.h"
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

/** The scene's topology at 64^3, each step's time printed. */
topo::SceneTopology topology64(vk::Context& ctx, const vk::GpuScene& gpuScene, const Scene& scene) {
    topo::TopologySettings s;
    s.resolution = 64;
    return topo::buildSceneTopology(ctx, gpuScene, scene, s, printTimer());
}

// The Cornell box (closed but for its front, two boxes inside) at 64^3: a skeleton, clusters that
// cover every node, and every empty voxel that a skeleton voxel reaches gets a cluster.
TEST_F(GpuTopology, CornellBoxTopologyLabelsTheEmptySpace) {
    Scene scene = makeCornellBox(CornellBoxParams{});
    scene.computeCaps();
    vk::GpuScene gpuScene(*m_ctx, scene);
    const topo::SceneTopology t = topology64(*m_ctx, gpuScene, scene);
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
    // The scene's bounds close the box's open front, so all the empty space is one piece.
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

// The two-room stress scene: the camera in room B sees room A's floor through the door. Every
// covered pixel (seen from the camera in room B, room A through the door) gets a valid cluster,
// and some pixels deep in each room sit in clusters of their own room only. Not all: the
// doorway's cluster reaches deep into both rooms here (techniques/topovpl/README.md, open).
TEST_F(GpuTopology, EveryTwoRoomPixelGetsACluster) {
    Scene scene =
        loadSceneFile(std::string(GILAB_SOURCE_DIR) + "/scenes/stress/two_rooms_door.json", "");
    scene.computeCaps();
    vk::GpuScene gpuScene(*m_ctx, scene);
    const topo::SceneTopology t = topology64(*m_ctx, gpuScene, scene);
    std::printf("two rooms 64^3: %u clusters, %zu gates\n", t.segmentation.clusterCount,
                t.gates.size());
    // The empty space ends at the scene's bounds, not at the cube grid's border
    // (the rooms are twice as long as high: most of the cube lies outside them). Every voxel
    // beyond them is solid, so no cluster and no skeleton voxel lies there.
    const glm::ivec3 lo = t.grid.voxelOf(scene.caps.bounds.lo) - topo::kBoundsMarginVoxels;
    const glm::ivec3 hi = t.grid.voxelOf(scene.caps.bounds.hi) + topo::kBoundsMarginVoxels;
    size_t outside = 0;
    for (uint32_t z = 0; z < t.dims.nz; ++z)
        for (uint32_t y = 0; y < t.dims.ny; ++y)
            for (uint32_t x = 0; x < t.dims.nx; ++x) {
                const glm::ivec3 c(x, y, z);
                if (glm::all(glm::greaterThanEqual(c, lo)) && glm::all(glm::lessThanEqual(c, hi)))
                    continue;
                ++outside;
                ASSERT_EQ(t.voxelCluster[t.dims.index(x, y, z)], topo::kNoNode)
                    << x << " " << y << " " << z;
            }
    EXPECT_GT(outside, t.dims.count() / 4);
    for (const glm::vec3& p : t.graph.position) {
        EXPECT_TRUE(glm::all(glm::greaterThanEqual(p, glm::vec3(lo))));
        EXPECT_TRUE(glm::all(glm::lessThanEqual(p, glm::vec3(hi))));
    }
    // No node is a clump of unthinned empty space.
    EXPECT_LT(topo::largestNodeSkeletonPercent(t.graph), 5.0f);
    const uint32_t w = uint32_t(scene.settings.width), h = uint32_t(scene.settings.height);
    SharedPasses passes(*m_ctx, gpuScene, w, h);
    topo::PixelClusters pixels(*m_ctx, passes.gbuffer(), t, "test");
    m_ctx->submitAndWait([&](VkCommandBuffer cmd) {
        passes.record(cmd, scene.camera);
        pixels.record(cmd, scene.camera.position);
    });
    const std::vector<float> pos = passes.gbuffer().position.readbackFloat(*m_ctx);
    const std::vector<uint8_t> raw = pixels.clusters().readback(*m_ctx);
    std::vector<uint32_t> ids(size_t(w) * h);
    ASSERT_EQ(raw.size(), ids.size() * 4);
    std::memcpy(ids.data(), raw.data(), raw.size());
    std::vector<std::pair<bool, uint32_t>>
        deep;  // (in room A, cluster) of pixels far from the wall
    size_t covered = 0, labelled = 0;
    const float wallLo = 0.5f, wallHi = 0.52f;  // the dividing wall's x range (generator defaults)
    for (size_t i = 0; i < size_t(w) * h; ++i) {
        if (pos[i * 4 + 3] < 0.5f) continue;
        ++covered;
        const uint32_t id = ids[i];
        if (id == topo::kNoNode) continue;
        ++labelled;
        ASSERT_LT(id, t.segmentation.clusterCount);
        const float x = pos[i * 4];
        if (x < wallLo - 0.2f || x > wallHi + 0.2f) deep.emplace_back(x < wallLo, id);
    }
    EXPECT_EQ(labelled, covered);
    std::set<uint32_t> roomA, roomB;
    for (const auto& [a, id] : deep)
        (a ? roomA : roomB).insert(id);
    size_t apart = 0;  // pixels whose cluster does not appear deep in the other room
    for (const auto& [a, id] : deep)
        apart += (a ? roomB : roomA).count(id) == 0;
    std::printf("%zu pixels deep in the rooms, %zu in clusters of one room only\n", deep.size(),
                apart);
    EXPECT_FALSE(roomA.empty());  // room A's floor is seen through the door
    EXPECT_FALSE(roomB.empty());
    // Every pixel deep in a room is in a cluster of that room only (with the gate at the doorway;
    // before it, 372 of 743: the doorway's cluster reached deep into both rooms).
    EXPECT_EQ(apart, deep.size());
}

}  // namespace
}  // namespace gilab
