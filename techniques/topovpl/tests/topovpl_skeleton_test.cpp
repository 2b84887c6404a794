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
#include "techniques/topovpl/cluster_merge.h"
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

/** EDT of the walls -> maximal balls; curve skeleton of the empty space; segmentation, then
 *  clusters and gates with or without our visibility merge. */
Topo segment(const Rooms& rooms, bool mergeVisible = true, float alpha = 0.2f,
             topo::GatePlacement placement = topo::GatePlacement::Midpoint) {
    const std::vector<float> dist = distanceTransform(rooms.solid, rooms.dims);
    std::vector<uint8_t> open(rooms.solid.size());
    for (size_t i = 0; i < open.size(); ++i)
        open[i] = rooms.solid[i] ? 0 : 1;
    std::vector<uint8_t> empty = open;
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
    t.seg = topo::segmentSkeleton(t.graph);
    topo::clusterSkeleton(t.graph, t.seg, alpha, open, rooms.dims, mergeVisible, placement);
    t.labels = topo::nearestNodeGrid(open, rooms.dims, voxels, t.graph.voxelNode);
    std::printf(
        "%zu skeleton voxels, %zu nodes, %zu kept (%u topology, %u curvature, %u coverage), "
        "%u greedy clusters, %s %u clusters, %zu gates\n",
        voxels.size(), t.graph.position.size(), t.seg.kept.size(), t.seg.topologyNodes,
        t.seg.curvatureNodes, t.seg.coverageNodes, t.seg.greedyClusters,
        mergeVisible ? "merged" : "unmerged", t.seg.clusterCount, t.seg.gates.size());
    if (std::getenv("TOPO_DEBUG"))
        for (uint32_t k : t.seg.kept)
            std::printf("  node %u at %.1f %.1f %.1f r %.2f kind %d cluster %u\n", k,
                        t.graph.position[k].x, t.graph.position[k].y, t.graph.position[k].z,
                        t.graph.maxball[k], int(t.seg.kind[k]), t.seg.cluster[k]);
    if (std::getenv("TOPO_DEBUG"))
        for (const topo::Gate& g : t.seg.gates)
            std::printf("  gate at %.1f %.1f %.1f n %.2f %.2f %.2f r %.2f (%.2f %.2f) %u-%u\n",
                        g.centre.x, g.centre.y, g.centre.z, g.normal.x, g.normal.y, g.normal.z,
                        g.radius, g.radiusA, g.radiusB, g.clusterA, g.clusterB);
    return t;
}

/** A straight chain of nodes 30 voxels apart (farther than any ball: every node is kept as a
 *  coverage node), radii as given. */
topo::SkeletonGraph chain(const std::vector<float>& radii, float spacing = 30.0f) {
    topo::SkeletonGraph g;
    for (size_t i = 0; i < radii.size(); ++i) {
        g.position.emplace_back(spacing * float(i), 0.0f, 0.0f);
        g.maxball.push_back(radii[i]);
        g.adjacency.emplace_back();
        if (i > 0) g.adjacency[i].push_back(uint32_t(i - 1));
        if (i + 1 < radii.size()) g.adjacency[i].push_back(uint32_t(i + 1));
        g.voxelNode.push_back(uint32_t(i));
    }
    return g;
}

// E3's two readings on radii that shrink by 0.8 voxel a node from 10: the seed rule
// (|r - R_C| <= 0.2 R_C) stops a cluster where the radius is 2 below the seed's; the chained
// rule (|r - r_m| <= 0.2 R_C) follows the gradual narrowing to the end.
TEST(CpuTopoSkeleton, ChainedClustersFollowAGradualNarrowing) {
    const topo::SkeletonGraph g = chain({10.0f, 9.2f, 8.4f, 7.6f, 6.8f, 6.0f});
    topo::Segmentation seed = topo::segmentSkeleton(g);
    ASSERT_EQ(seed.kept.size(), 6u);
    topo::Segmentation chained = seed;
    topo::clusterSkeleton(g, seed, 0.2f, {}, GridDims{}, false, topo::GatePlacement::Midpoint, 1.0f,
                          topo::ClusterRule::Seed);
    topo::clusterSkeleton(g, chained, 0.2f, {}, GridDims{}, false, topo::GatePlacement::Midpoint,
                          1.0f, topo::ClusterRule::Chained);
    // Seed: {10, 9.2, 8.4} (7.6 is 2.4 below 10), {7.6, 6.8} (6.0 is 1.6 > 0.2 x 7.6 below), {6}.
    EXPECT_EQ(seed.cluster, (std::vector<uint32_t>{0, 0, 0, 1, 1, 2}));
    EXPECT_EQ(seed.gates.size(), 2u);
    EXPECT_EQ(chained.clusterCount, 1u);
    EXPECT_TRUE(chained.gates.empty());
}

// Chessboard balls are cubes: a node at (d, d, d) from a centre of radius d is inside it, and
// outside the Euclidean ball of the same radius.
TEST(CpuTopoSkeleton, ChessboardBallsAreCubes) {
    topo::SkeletonGraph g = chain({4.0f, 1.0f}, 10.0f);
    const glm::vec3 corner = g.position[0] + glm::vec3(4.0f, 4.0f, -4.0f);
    EXPECT_FALSE(g.inBall(0, corner));
    EXPECT_NEAR(g.ballDistance(0, corner), std::sqrt(48.0f), 1e-5f);
    g.metric = topo::BallMetric::Chessboard;
    EXPECT_TRUE(g.inBall(0, corner));
    EXPECT_FLOAT_EQ(g.ballDistance(0, corner), 4.0f);
    EXPECT_FALSE(g.inBall(0, corner + glm::vec3(0.0f, 0.01f, 0.0f)));
}

// E2's split point on a line a - n1 - n2 - n3 - b whose middle node n2 has a ball of 12 that
// covers n1 and n3: splitting at the most uncovered node (n2) keeps one coverage node; splitting
// at the first (n1) keeps n1, then n2.
TEST(CpuTopoSkeleton, CoverageSplitAtTheMostUncoveredNode) {
    topo::SkeletonGraph g = chain({5.0f, 1.0f, 12.0f, 1.0f, 5.0f});
    g.position = {{0, 0, 0}, {6, 0, 0}, {15, 0, 0}, {24, 0, 0}, {30, 0, 0}};
    const topo::Segmentation first = topo::segmentSkeleton(g, topo::CoverageSplit::First);
    const topo::Segmentation most = topo::segmentSkeleton(g, topo::CoverageSplit::Most);
    EXPECT_EQ(first.coverageNodes, 2u);
    EXPECT_EQ(first.kind[1], topo::NodeKind::Coverage);
    EXPECT_EQ(first.kind[2], topo::NodeKind::Coverage);
    EXPECT_EQ(most.coverageNodes, 1u);
    EXPECT_EQ(most.kind[2], topo::NodeKind::Coverage);
    EXPECT_EQ(most.kind[1], topo::NodeKind::Line);
    EXPECT_EQ(most.kind[3], topo::NodeKind::Line);
    // The line nodes map to the nearer kept node.
    EXPECT_EQ(most.segmentedNode[1], 0u);
    EXPECT_EQ(most.segmentedNode[3], 4u);
}

// A node that holds most of the skeleton's voxels (a clump of empty space that did not thin).
TEST(CpuTopoSkeleton, LargestNodeShareOfTheSkeleton) {
    topo::SkeletonGraph g = chain({1.0f, 1.0f, 1.0f});
    g.voxelNode = {0, 1, 1, 1, 2, 1, 1, 1};
    uint32_t node = 99;
    EXPECT_FLOAT_EQ(topo::largestNodeSkeletonPercent(g, &node), 75.0f);
    EXPECT_EQ(node, 1u);
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
    for (glm::uvec3 size : {glm::uvec3(24, 16, 20), glm::uvec3(30, 12, 12), glm::uvec3(16),
                            glm::uvec3(40, 10, 10), glm::uvec3(22, 22, 8)}) {
        for (bool merge : {true, false}) {
            const Topo t = segment(closedBox(size.x, size.y, size.z), merge);
            ASSERT_FALSE(t.graph.position.empty());
            EXPECT_EQ(t.seg.clusterCount, 1u)
                << size.x << "x" << size.y << "x" << size.z << " merge " << merge;
            EXPECT_TRUE(t.seg.gates.empty());
        }
    }
}

/** Two 18 x 14 x 14 rooms (x 1-18 and 21-38) behind a two-voxel wall (x 19-20) with a 4 x 4 door
 *  (y, z 6-9) in its middle. */
Rooms twoRooms() {
    Rooms r = closedBox(40, 16, 16);
    r.fill({19, 1, 1}, {20, 14, 14}, 1);
    r.fill({19, 6, 6}, {20, 9, 9}, 0);
    return r;
}

uint32_t nearestNode(const Topo& t, glm::vec3 p) {
    uint32_t best = 0;
    for (uint32_t i = 1; i < t.graph.position.size(); ++i)
        if (glm::length(t.graph.position[i] - p) < glm::length(t.graph.position[best] - p))
            best = i;
    return best;
}

// Two rooms joined by a door: with our visibility merge, exactly two clusters (one per room) and
// one gate, just before the doorway, across the wall (the paper's greedy rule alone gives 4 and
// 3: see the next test).
TEST(CpuTopoSkeleton, TwoRoomsAreTwoClustersWithOneGateAtTheDoor) {
    const Rooms r = twoRooms();
    const Topo t = segment(r);
    EXPECT_EQ(t.seg.clusterCount, 2u);
    EXPECT_EQ(t.seg.greedyClusters, 4u);
    ASSERT_EQ(t.seg.gates.size(), 1u);
    const uint32_t a = t.seg.cluster[nearestNode(t, {9.5f, 7.5f, 7.5f})];
    const uint32_t b = t.seg.cluster[nearestNode(t, {30.0f, 7.5f, 7.5f})];
    EXPECT_NE(a, b);
    const topo::Gate& g = t.seg.gates.front();
    EXPECT_TRUE((g.clusterA == a && g.clusterB == b) || (g.clusterA == b && g.clusterB == a));
    EXPECT_GT(std::abs(g.normal.x), 0.99f);  // across the wall
    // The doorway's centre in voxel coordinates (the graph's): x between voxels 19 and 20, y and
    // z between 7 and 8. The gate is the midpoint of the segmented edge into the door's node.
    EXPECT_LE(glm::length(g.centre - glm::vec3(19.5f, 7.5f, 7.5f)), 2.2f);
    EXPECT_EQ(g.radius, std::min(g.radiusA, g.radiusB));
    EXPECT_LE(g.radius, 2.0f + 1e-4f);    // no wider than the door's half-width
    EXPECT_GT(g.radiusA, g.radiusB);      // from room A's approach into the door
    EXPECT_NEAR(g.radiusB, 2.0f, 1e-4f);  // the door node's ball

    // Every empty voxel of a room is labelled (nearest node through the empty space) with its
    // own room's cluster: room A's up to the gate's plane (x 1-16), all of room B's (x 21-38).
    // Between the gate and the wall (x 17-18, room A's side) labels may take room B's cluster,
    // whose door node's line reaches there.
    uint32_t checked = 0;
    for (uint32_t z = 1; z < 15; ++z)
        for (uint32_t y = 1; y < 15; ++y)
            for (uint32_t x = 1; x < 39; ++x) {
                const size_t i = r.dims.index(x, y, z);
                if (r.solid[i]) {
                    EXPECT_EQ(t.labels[i], topo::kNoNode);
                    continue;
                }
                ASSERT_NE(t.labels[i], topo::kNoNode) << x << " " << y << " " << z;
                const uint32_t c = t.seg.cluster[t.labels[i]];
                if (float(x) + 0.5f < g.centre.x) {
                    EXPECT_EQ(c, a) << x << " " << y << " " << z;
                    ++checked;
                } else if (x >= 21) {
                    EXPECT_EQ(c, b) << x << " " << y << " " << z;
                    ++checked;
                }
            }
    EXPECT_EQ(checked, (16u + 18u) * 14u * 14u);
}

// Our bottleneck placement puts the one gate in the doorway itself (the narrowest node of its
// line), with the door's half-width as its neck radius, and the line's nodes on each side in
// that side's cluster: every empty voxel of room A (x 1-18) is in A's cluster, every one of room
// B (x 21-38) in B's, with no band of the wrong cluster before the door.
TEST(CpuTopoSkeleton, BottleneckGateSitsInTheDoorway) {
    const Rooms r = twoRooms();
    const Topo t = segment(r, true, 0.2f, topo::GatePlacement::Bottleneck);
    EXPECT_EQ(t.seg.clusterCount, 2u);
    ASSERT_EQ(t.seg.gates.size(), 1u);
    const topo::Gate& g = t.seg.gates.front();
    EXPECT_LE(glm::length(g.centre - glm::vec3(19.5f, 7.5f, 7.5f)), 0.9f);
    EXPECT_GT(std::abs(g.normal.x), 0.99f);
    EXPECT_NEAR(g.radiusNeck, 2.0f, 1e-4f);
    EXPECT_LE(g.radiusNeck, g.radius);
    const uint32_t a = t.seg.cluster[nearestNode(t, {9.5f, 7.5f, 7.5f})];
    const uint32_t b = t.seg.cluster[nearestNode(t, {30.0f, 7.5f, 7.5f})];
    ASSERT_NE(a, b);
    uint32_t checked = 0;
    for (uint32_t z = 1; z < 15; ++z)
        for (uint32_t y = 1; y < 15; ++y)
            for (uint32_t x = 1; x < 39; ++x) {
                const size_t i = r.dims.index(x, y, z);
                if (r.solid[i] || (x > 18 && x < 21)) continue;
                ASSERT_NE(t.labels[i], topo::kNoNode);
                EXPECT_EQ(t.seg.cluster[t.labels[i]], x <= 18 ? a : b) << x << " " << y << " " << z;
                ++checked;
            }
    EXPECT_EQ(checked, (18u + 18u) * 14u * 14u);
}

// mergeVisible = false is the paper's literal greedy clustering, as before the merge existed:
// the approaches to the door are clusters of their own (4 clusters, 3 gates), and it equals
// segmentSkeleton(graph, alpha).
TEST(CpuTopoSkeleton, WithoutTheMergeTheGreedyClustersAreLiteral) {
    const Topo t = segment(twoRooms(), false);
    EXPECT_GE(t.seg.clusterCount, 4u);
    EXPECT_GE(t.seg.gates.size(), 3u);
    EXPECT_EQ(t.seg.greedyClusters, t.seg.clusterCount);
    const topo::Segmentation literal = topo::segmentSkeleton(t.graph, 0.2f);
    EXPECT_EQ(literal.cluster, t.seg.cluster);
    EXPECT_EQ(literal.clusterCount, t.seg.clusterCount);
    ASSERT_EQ(literal.gates.size(), t.seg.gates.size());
    for (size_t i = 0; i < literal.gates.size(); ++i) {
        EXPECT_EQ(literal.gates[i].centre, t.seg.gates[i].centre);
        EXPECT_EQ(literal.gates[i].clusterA, t.seg.gates[i].clusterA);
        EXPECT_EQ(literal.gates[i].clusterB, t.seg.gates[i].clusterB);
    }
    // The merge only joins clusters: each merged cluster is a union of literal ones.
    const Topo m = segment(twoRooms(), true);
    ASSERT_EQ(m.seg.cluster.size(), t.seg.cluster.size());
    std::vector<uint32_t> into(t.seg.clusterCount, topo::kNoNode);
    for (size_t i = 0; i < t.seg.cluster.size(); ++i) {
        uint32_t& c = into[t.seg.cluster[i]];
        if (c == topo::kNoNode) c = m.seg.cluster[i];
        EXPECT_EQ(c, m.seg.cluster[i]) << i;
    }
}

// Around a corner nothing sees across the inner edge, so the merge must keep what the greedy
// rule split there. An L corridor whose legs differ in width (6 x 6 along y, 10 x 10 along x):
// two clusters, one per leg, the gate where the narrow leg leaves the wide one. A room with two
// 6 x 6 corridors leaving it along x and along y: three clusters.
TEST(CpuTopoSkeleton, TheMergeDoesNotTurnACorner) {
    Rooms l;
    l.dims = {40, 40, 12};
    l.solid.assign(l.dims.count(), 1);
    l.fill({1, 1, 1}, {6, 38, 6}, 0);
    l.fill({1, 1, 1}, {38, 10, 10}, 0);
    const Topo t = segment(l);
    EXPECT_EQ(t.seg.clusterCount, 2u);
    ASSERT_EQ(t.seg.gates.size(), 1u);
    const uint32_t narrow = t.seg.cluster[nearestNode(t, {3.0f, 35.0f, 3.0f})];
    const uint32_t wide = t.seg.cluster[nearestNode(t, {34.0f, 5.0f, 5.0f})];
    EXPECT_NE(narrow, wide);
    const topo::Gate& g = t.seg.gates.front();
    EXPECT_GT(std::abs(g.normal.y), 0.9f);  // along the narrow leg
    EXPECT_NEAR(g.centre.y, 11.0f, 2.0f);   // where it leaves the wide one (y 10 -> 11)
    EXPECT_LT(g.centre.x, 7.0f);

    Rooms arms;
    arms.dims = {40, 40, 12};
    arms.solid.assign(arms.dims.count(), 1);
    arms.fill({1, 1, 1}, {16, 16, 10}, 0);  // the room
    arms.fill({1, 1, 1}, {6, 38, 6}, 0);    // a corridor along y
    arms.fill({1, 1, 1}, {38, 6, 6}, 0);    // one along x
    const Topo a = segment(arms);
    EXPECT_EQ(a.seg.clusterCount, 3u);
    EXPECT_EQ(a.seg.gates.size(), 2u);
    const uint32_t room = a.seg.cluster[nearestNode(a, {8.0f, 8.0f, 5.0f})];
    const uint32_t armY = a.seg.cluster[nearestNode(a, {3.0f, 35.0f, 3.0f})];
    const uint32_t armX = a.seg.cluster[nearestNode(a, {35.0f, 3.0f, 3.0f})];
    EXPECT_NE(room, armY);
    EXPECT_NE(room, armX);
    EXPECT_NE(armX, armY);
    for (const topo::Gate& gate : a.seg.gates)
        EXPECT_TRUE(gate.clusterA == room || gate.clusterB == room);  // each arm meets the room
}

/** Reference for segmentVisible: every voxel whose closed cube the segment between the voxel
 *  centres of a and b touches, by exact rational slab tests (times doubled: integers). */
bool visibleByBruteForce(const std::vector<uint8_t>& empty, const GridDims& dims, glm::ivec3 a,
                         glm::ivec3 b) {
    const glm::ivec3 d = b - a;
    const glm::ivec3 lo = glm::min(a, b) - 1, hi = glm::max(a, b) + 1;
    for (int z = lo.z; z <= hi.z; ++z)
        for (int y = lo.y; y <= hi.y; ++y)
            for (int x = lo.x; x <= hi.x; ++x) {
                const glm::ivec3 v(x, y, z);
                // t in [0, 1] as num / den with den > 0: the touched interval [tLo, tHi].
                long tLoN = 0, tLoD = 1, tHiN = 1, tHiD = 1;
                bool touches = true;
                for (int i = 0; i < 3 && touches; ++i) {
                    if (d[i] == 0) {
                        touches = v[i] == a[i];
                        continue;
                    }
                    // Planes v_i and v_i + 1: t = (2 v_i - 2 a_i - 1) / (2 d_i), and + 2.
                    long n0 = 2L * v[i] - 2L * a[i] - 1, n1 = n0 + 2, den = 2L * d[i];
                    if (den < 0) {
                        n0 = -n0;
                        n1 = -n1;
                        den = -den;
                    }
                    if (n0 > n1) std::swap(n0, n1);
                    if (n0 * tLoD > tLoN * den) {
                        tLoN = n0;
                        tLoD = den;
                    }
                    if (n1 * tHiD < tHiN * den) {
                        tHiN = n1;
                        tHiD = den;
                    }
                    touches = tLoN * tHiD <= tHiN * tLoD;
                }
                if (!touches) continue;
                const bool inside = x >= 0 && y >= 0 && z >= 0 && uint32_t(x) < dims.nx &&
                                    uint32_t(y) < dims.ny && uint32_t(z) < dims.nz;
                if (!inside || !empty[dims.index(uint32_t(x), uint32_t(y), uint32_t(z))])
                    return false;
            }
    return true;
}

TEST(CpuTopoSkeleton, SegmentVisibilityIsExact) {
    const GridDims dims{12, 10, 8};
    std::vector<uint8_t> empty(dims.count(), 1);
    auto set = [&](int x, int y, int z, uint8_t v) {
        empty[dims.index(uint32_t(x), uint32_t(y), uint32_t(z))] = v;
    };
    // Open space: any two voxels see each other, including themselves.
    EXPECT_TRUE(topo::segmentVisible(empty, dims, {0, 0, 0}, {11, 9, 7}));
    EXPECT_TRUE(topo::segmentVisible(empty, dims, {3, 4, 5}, {3, 4, 5}));
    // A wall x = 6 between two points blocks; a hole in it on the line lets them see.
    for (int z = 0; z < 8; ++z)
        for (int y = 0; y < 10; ++y)
            set(6, y, z, 0);
    EXPECT_FALSE(topo::segmentVisible(empty, dims, {2, 5, 4}, {10, 5, 4}));
    EXPECT_FALSE(topo::segmentVisible(empty, dims, {10, 5, 4}, {2, 5, 4}));
    set(6, 5, 4, 1);
    EXPECT_TRUE(topo::segmentVisible(empty, dims, {2, 5, 4}, {10, 5, 4}));
    // The segment joins voxel centres: from (2, 5, 4) to (10, 7, 4) it crosses x = 6.5 at
    // y = 6.5 (in voxel centre units), i.e. in voxel (6, 6): the hole at (6, 5) is not on it.
    EXPECT_FALSE(topo::segmentVisible(empty, dims, {2, 5, 4}, {10, 7, 4}));
    set(6, 6, 4, 1);
    EXPECT_TRUE(topo::segmentVisible(empty, dims, {2, 5, 4}, {10, 7, 4}));
    // A solid end, or one outside the grid, is not visible.
    EXPECT_FALSE(topo::segmentVisible(empty, dims, {6, 0, 0}, {6, 0, 0}));
    EXPECT_FALSE(topo::segmentVisible(empty, dims, {0, 0, 0}, {-1, 0, 0}));
    // Through an edge: (0, 0) to (2, 2) passes the edge shared by (1, 0) and (0, 1); one of them
    // solid blocks it (supercover), as a diagonal pair of solid voxels does.
    std::fill(empty.begin(), empty.end(), 1);
    set(1, 0, 0, 0);
    EXPECT_FALSE(topo::segmentVisible(empty, dims, {0, 0, 0}, {2, 2, 0}));
    EXPECT_TRUE(topo::segmentVisible(empty, dims, {0, 1, 0}, {2, 3, 0}));
    // Through a corner: (0, 0, 0) to (2, 2, 2) touches all 8 voxels around (1, 1, 1).
    std::fill(empty.begin(), empty.end(), 1);
    set(0, 1, 1, 0);
    EXPECT_FALSE(topo::segmentVisible(empty, dims, {0, 0, 0}, {2, 2, 2}));

    // Random grids: exactly the closed-cube supercover, symmetric.
    uint32_t state = 12345u, blocked = 0, seen = 0;
    auto rnd = [&](uint32_t n) {
        state = state * 1664525u + 1013904223u;
        return (state >> 8) % n;
    };
    for (int trial = 0; trial < 4000; ++trial) {
        if (trial % 100 == 0)
            for (uint8_t& e : empty)
                e = rnd(100) < 8 ? 0 : 1;
        const glm::ivec3 a(rnd(12), rnd(10), rnd(8)), b(rnd(12), rnd(10), rnd(8));
        const bool v = topo::segmentVisible(empty, dims, a, b);
        ASSERT_EQ(v, visibleByBruteForce(empty, dims, a, b))
            << a.x << " " << a.y << " " << a.z << " -> " << b.x << " " << b.y << " " << b.z;
        ASSERT_EQ(v, topo::segmentVisible(empty, dims, b, a));
        (v ? seen : blocked) += 1;
    }
    EXPECT_GT(seen, 200u);  // both outcomes are exercised
    EXPECT_GT(blocked, 200u);
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
    EXPECT_GE(t.seg.clusterCount, 3u);  // three rooms along the S, merge or not
    EXPECT_GE(t.seg.gates.size(), 2u);
    const Topo literal = segment(r, false);
    EXPECT_GE(literal.seg.clusterCount, t.seg.clusterCount);
}

}  // namespace
}  // namespace gilab
