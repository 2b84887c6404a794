// The topological segmentation of empty space (Noël & Biri 2014; techniques/topovpl/
// skeleton_graph.h) on synthetic voxel grids: distance transform, curve thinning, segmentation,
// clusters and gates. CPU only.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include <gtest/gtest.h>

#include "core/voxel/distance_transform.h"
#include "core/voxel/thinning.h"
#include "techniques/topovpl/nearest_node.h"
#include "techniques/topovpl/skeleton_graph.h"

namespace gilab {
namespace {

struct Rooms {
    GridDims dims;
    std::vector<uint8_t> solid;
    void fill(glm::ivec3 lo, glm::ivec3 hi, uint8_t v) {  // inclusive box
        for (int z = lo.z; z <= hi.z; ++z)
            for (int y = lo.y; y <= hi.y; ++y)
                for (int x = lo.x; x <= hi.x; ++x)
                    solid[dims.index(uint32_t(x), uint32_t(y), uint32_t(z))] = v;
    }
};

/** A closed box of one-voxel walls around an empty inside. */
Rooms closedBox(uint32_t nx, uint32_t ny, uint32_t nz) {
    Rooms r;
    r.dims = {nx, ny, nz};
    r.solid.assign(r.dims.count(), 1);
    r.fill({1, 1, 1}, {int(nx) - 2, int(ny) - 2, int(nz) - 2}, 0);
    return r;
}

struct Topo {
    topo::SkeletonGraph graph;
    topo::Segmentation seg;
    std::vector<uint32_t> labels;  // nearest-node grid
};

/** EDT of the walls -> maximal balls; curve skeleton of the empty space; segmentation. */
Topo segment(const Rooms& rooms, float alpha = 0.2f) {
    const std::vector<float> dist = distanceTransform(rooms.solid, rooms.dims);
    std::vector<uint8_t> empty(rooms.solid.size());
    for (size_t i = 0; i < empty.size(); ++i)
        empty[i] = rooms.solid[i] ? 0 : 1;
    thinCurveSkeleton(empty, rooms.dims);
    std::vector<glm::ivec3> voxels;
    std::vector<float> radii;
    for (uint32_t z = 0; z < rooms.dims.nz; ++z)
        for (uint32_t y = 0; y < rooms.dims.ny; ++y)
            for (uint32_t x = 0; x < rooms.dims.nx; ++x)
                if (empty[rooms.dims.index(x, y, z)]) {
                    voxels.emplace_back(x, y, z);
                    radii.push_back(dist[rooms.dims.index(x, y, z)]);
                }
    Topo t;
    t.graph = topo::buildSkeletonGraph(voxels, radii);
    t.seg = topo::segmentSkeleton(t.graph, alpha);
    std::vector<uint8_t> open(rooms.solid.size());
    for (size_t i = 0; i < open.size(); ++i)
        open[i] = rooms.solid[i] ? 0 : 1;
    t.labels = topo::nearestNodeGrid(open, rooms.dims, voxels, t.graph.voxelNode);
    std::printf(
        "%zu skeleton voxels, %zu nodes, %zu kept (%u topology, %u curvature, %u coverage), "
        "%u clusters, %zu gates\n",
        voxels.size(), t.graph.position.size(), t.seg.kept.size(), t.seg.topologyNodes,
        t.seg.curvatureNodes, t.seg.coverageNodes, t.seg.clusterCount, t.seg.gates.size());
    if (std::getenv("TOPO_DEBUG"))
        for (uint32_t k : t.seg.kept)
            std::printf("  node %u at %.1f %.1f %.1f r %.2f kind %d cluster %u\n", k,
                        t.graph.position[k].x, t.graph.position[k].y, t.graph.position[k].z,
                        t.graph.maxball[k], int(t.seg.kind[k]), t.seg.cluster[k]);
    return t;
}

// A line with two side branches at its middle: the short one lies inside the junction's maximal
// ball and is pruned (its voxels map to the junction); the long one is kept.
TEST(CpuTopoSkeleton, CoveredSpursArePruned) {
    std::vector<glm::ivec3> voxels;
    std::vector<float> radii;
    for (int x = 0; x <= 20; ++x) {
        voxels.emplace_back(x, 0, 0);
        radii.push_back(x == 10 ? 4.0f : 2.0f);
    }
    for (int y = 1; y <= 3; ++y) {  // short branch: tip 3 from the junction, radius 4
        voxels.emplace_back(10, y, 0);
        radii.push_back(1.0f);
    }
    for (int z = 1; z <= 9; ++z) {  // long branch: tip 9 away
        voxels.emplace_back(10, 0, z);
        radii.push_back(1.0f);
    }
    const topo::SkeletonGraph pruned = topo::buildSkeletonGraph(voxels, radii);
    const topo::SkeletonGraph full = topo::buildSkeletonGraph(voxels, radii, false);
    EXPECT_EQ(full.prunedNodes, 0u);
    EXPECT_GE(pruned.prunedNodes, 2u);
    EXPECT_EQ(pruned.position.size() + pruned.prunedNodes, full.position.size());
    // The long branch's tip survives as a degree-1 node; the short branch's voxels map to the
    // junction's node.
    const uint32_t junction = pruned.voxelNode[10];
    EXPECT_EQ(pruned.voxelNode[21 + 2], junction);  // (10, 3, 0), the short tip
    const uint32_t longTip = pruned.voxelNode[voxels.size() - 1];
    EXPECT_EQ(pruned.adjacency[longTip].size(), 1u);
    EXPECT_EQ(glm::ivec3(pruned.position[longTip]), glm::ivec3(10, 0, 9));
}

TEST(CpuTopoSkeleton, ClosedBoxIsOneCluster) {
    for (glm::uvec3 size : {glm::uvec3(24, 16, 20), glm::uvec3(30, 12, 12), glm::uvec3(16)}) {
        const Topo t = segment(closedBox(size.x, size.y, size.z));
        ASSERT_FALSE(t.graph.position.empty());
        EXPECT_EQ(t.seg.clusterCount, 1u) << size.x << "x" << size.y << "x" << size.z;
        EXPECT_TRUE(t.seg.gates.empty());
    }
}

// Two rooms joined by a door: the rooms' centres fall in different clusters and a gate stands in
// or just before the doorway, across the wall. (The paper's rule also cuts the approach to the
// door into its own clusters here, so the count is not asserted: issue 14 keeps it open.)
TEST(CpuTopoSkeleton, TwoRoomsAreSeparatedByAGateAtTheDoor) {
    Rooms r = closedBox(40, 16, 16);
    r.fill({19, 1, 1}, {20, 14, 14}, 1);  // the dividing wall, two voxels thick
    r.fill({19, 6, 6}, {20, 9, 9}, 0);    // a 4 x 4 door in its middle
    const Topo t = segment(r);
    auto nearest = [&](glm::vec3 p) {
        uint32_t best = 0;
        for (uint32_t i = 1; i < t.graph.position.size(); ++i)
            if (glm::length(t.graph.position[i] - p) < glm::length(t.graph.position[best] - p))
                best = i;
        return best;
    };
    const uint32_t a = nearest({9.5f, 7.5f, 7.5f}), b = nearest({30.0f, 7.5f, 7.5f});
    EXPECT_NE(t.seg.cluster[a], t.seg.cluster[b]);
    EXPECT_GE(t.seg.clusterCount, 2u);
    float closest = 1e30f;
    for (const topo::Gate& g : t.seg.gates) {
        EXPECT_NE(g.clusterA, g.clusterB);
        EXPECT_GT(std::abs(g.normal.x), 0.7f);  // across the wall
        closest = std::min(closest, glm::length(g.centre - glm::vec3(19.5f, 7.5f, 7.5f)));
    }
    EXPECT_LT(closest, 3.0f);  // a gate in or just before the doorway

    // The nearest-node grid never labels a voxel across the wall: deep inside each room (away
    // from the door) every empty voxel maps to a node on its own side of the wall.
    for (uint32_t z = 1; z < 15; ++z)
        for (uint32_t y = 1; y < 15; ++y)
            for (uint32_t x = 1; x < 39; ++x) {
                const size_t i = r.dims.index(x, y, z);
                if (r.solid[i]) {
                    EXPECT_EQ(t.labels[i], topo::kNoNode);
                    continue;
                }
                ASSERT_NE(t.labels[i], topo::kNoNode) << x << " " << y << " " << z;
                const float nodeX = t.graph.position[t.labels[i]].x;
                if (x < 14) {
                    EXPECT_LT(nodeX, 19.0f) << x << " " << y << " " << z;
                }
                if (x > 25) {
                    EXPECT_GT(nodeX, 20.0f) << x << " " << y << " " << z;
                }
            }
}

TEST(CpuTopoSkeleton, EveryNodeIsClusteredAndLinesMapToKeptNodes) {
    Rooms r = closedBox(36, 20, 14);
    r.fill({12, 1, 1}, {12, 12, 12}, 1);  // a wall with a gap at the top
    r.fill({24, 7, 1}, {24, 18, 12}, 1);  // and one with a gap at the bottom: an S-shaped path
    const Topo t = segment(r);
    const uint32_t n = uint32_t(t.graph.position.size());
    for (uint32_t i = 0; i < n; ++i) {
        EXPECT_LT(t.seg.cluster[i], t.seg.clusterCount) << i;
        const uint32_t k = t.seg.segmentedNode[i];
        EXPECT_NE(t.seg.kind[k], topo::NodeKind::Line) << i;
    }
    EXPECT_GE(t.seg.clusterCount, 3u);  // three rooms along the S
    EXPECT_GE(t.seg.gates.size(), 2u);
}

}  // namespace
}  // namespace gilab
