// The nearest-node grid (techniques/topovpl/nearest_node.h): the bucket-queue version against the
// heap version on synthetic grids (rooms and a door, random obstacles, a corridor with pillars,
// a wall without a door): the same unreached voxels and at most 0.2 % of the labels changed
// (the contract), in fact none (the bucket version reproduces the heap's ties); exact equality
// where no two nodes tie, determinism, input errors, and the time of both on a 160^3 grid
// (printed). CPU only.
#include <algorithm>
#include <chrono>
#include <iostream>
#include <random>
#include <set>
#include <vector>

#include <gtest/gtest.h>

#include "core/util/error.h"
#include "techniques/topovpl/nearest_node.h"

namespace gilab {
namespace {

using topo::kNoNode;

struct Grid {
    GridDims dims;
    std::vector<uint8_t> empty;
    std::vector<glm::ivec3> seeds;  // skeleton voxels
    std::vector<uint32_t> nodes;    // their nodes: one per skeleton voxel unless said otherwise

    Grid(uint32_t nx, uint32_t ny, uint32_t nz) : dims{nx, ny, nz}, empty(dims.count(), 1) {}

    size_t at(glm::ivec3 v) const {
        return dims.index(uint32_t(v.x), uint32_t(v.y), uint32_t(v.z));
    }
    bool inside(glm::ivec3 v) const {
        return v.x >= 0 && v.y >= 0 && v.z >= 0 && v.x < int(dims.nx) && v.y < int(dims.ny) &&
               v.z < int(dims.nz);
    }
    /** Sets an inclusive box, clipped to the grid, empty (1) or solid (0). */
    void fill(glm::ivec3 lo, glm::ivec3 hi, uint8_t value) {
        lo = glm::max(lo, glm::ivec3(0));
        hi = glm::min(hi, glm::ivec3(dims.nx, dims.ny, dims.nz) - 1);
        for (int z = lo.z; z <= hi.z; ++z)
            for (int y = lo.y; y <= hi.y; ++y)
                for (int x = lo.x; x <= hi.x; ++x)
                    empty[at({x, y, z})] = value;
    }
    /** Skeleton voxels on the segment a-b (26-connected), each its own node; solid voxels and
     *  voxels already listed are left out. */
    void line(glm::ivec3 a, glm::ivec3 b) {
        const glm::ivec3 d = glm::abs(b - a);
        const int steps = std::max({d.x, d.y, d.z, 1});
        for (int t = 0; t <= steps; ++t) {
            const glm::vec3 p = glm::vec3(a) + glm::vec3(b - a) * (float(t) / float(steps));
            const glm::ivec3 v(glm::round(p));
            if (!inside(v) || !empty[at(v)] ||
                std::find(seeds.begin(), seeds.end(), v) != seeds.end())
                continue;
            seeds.push_back(v);
            nodes.push_back(uint32_t(nodes.size()));
        }
    }
    /** Each voxel solid with probability `share` (raw mt19937 draws: the same on every
     *  standard library). */
    void randomSolids(double share, uint32_t seed) {
        std::mt19937 rng(seed);
        const uint32_t threshold = uint32_t(share * 4294967296.0);
        for (uint8_t& e : empty)
            if (rng() < threshold) e = 0;
    }
};

struct Comparison {
    size_t emptyVoxels = 0, reached = 0, changed = 0;
    double share() const { return emptyVoxels ? double(changed) / double(emptyVoxels) : 0.0; }
};

/** Both versions on g: the same voxels left without a node, labels that are nodes of g, and
 *  the count of empty voxels whose label differs. */
Comparison compare(const Grid& g, const std::vector<uint32_t>& fast,
                   const std::vector<uint32_t>& exact) {
    Comparison c;
    EXPECT_EQ(fast.size(), g.dims.count());
    EXPECT_EQ(exact.size(), g.dims.count());
    const std::set<uint32_t> nodes(g.nodes.begin(), g.nodes.end());
    size_t unreachedMismatch = 0, solidLabelled = 0, foreign = 0;
    for (size_t i = 0; i < g.dims.count(); ++i) {
        if (!g.empty[i]) {
            solidLabelled += fast[i] != kNoNode;
            continue;
        }
        ++c.emptyVoxels;
        if ((fast[i] == kNoNode) != (exact[i] == kNoNode)) {
            ++unreachedMismatch;
            continue;
        }
        if (fast[i] == kNoNode) continue;
        ++c.reached;
        foreign += !nodes.count(fast[i]);
        c.changed += fast[i] != exact[i];
    }
    EXPECT_EQ(unreachedMismatch, 0u) << "voxels reached by one version only";
    EXPECT_EQ(solidLabelled, 0u) << "solid voxels with a node";
    EXPECT_EQ(foreign, 0u) << "labels that are no node of the skeleton";
    return c;
}

Comparison compareOn(const Grid& g, const char* name) {
    const std::vector<uint32_t> fast = topo::nearestNodeGrid(g.empty, g.dims, g.seeds, g.nodes);
    const std::vector<uint32_t> exact =
        topo::nearestNodeGridExact(g.empty, g.dims, g.seeds, g.nodes);
    const Comparison c = compare(g, fast, exact);
    std::cout << name << ": " << g.seeds.size() << " skeleton voxels, " << c.emptyVoxels
              << " empty voxels, " << c.reached << " reached, " << c.changed << " labels changed ("
              << 100.0 * c.share() << " %)\n";
    EXPECT_GT(c.reached, 0u);
    EXPECT_LE(c.share(), 0.002) << name;
    EXPECT_EQ(c.changed, 0u) << name << ": the bucket version settles ties as the heap does";
    return c;
}

/** Two 30-voxel rooms side by side along x, a 2-voxel wall between them with a door, closed by
 *  one-voxel walls; skeleton: a line along each room and one through the door. */
Grid twoRooms() {
    Grid g(64, 34, 34);
    g.fill({0, 0, 0}, {63, 33, 33}, 0);
    g.fill({1, 1, 1}, {62, 32, 32}, 1);
    g.fill({31, 1, 1}, {32, 32, 32}, 0);   // the wall
    g.fill({31, 12, 1}, {32, 21, 16}, 1);  // the door: 10 wide, 16 high
    g.line({6, 16, 16}, {26, 16, 16});
    g.line({16, 4, 16}, {16, 29, 16});
    g.line({26, 16, 10}, {37, 16, 10});  // through the door
    g.line({37, 16, 16}, {57, 16, 16});
    g.line({47, 16, 5}, {47, 16, 28});
    return g;
}

TEST(CpuTopoNearest, TwoRoomsAndADoor) {
    compareOn(twoRooms(), "two rooms");
}

/** Random solid voxels, a sealed hollow box (its inside unreachable: kNoNode in both versions)
 *  and four skeleton lines that miss the box. */
Grid randomGrid(double share, uint32_t seed) {
    Grid g(64, 64, 64);
    g.randomSolids(share, seed);
    g.fill({48, 40, 8}, {55, 47, 15}, 0);
    g.fill({50, 42, 10}, {53, 45, 13}, 1);
    g.line({4, 4, 4}, {59, 59, 59});
    g.line({4, 59, 10}, {59, 4, 50});
    g.line({32, 2, 32}, {32, 61, 32});
    g.line({2, 20, 50}, {61, 20, 50});
    return g;
}

TEST(CpuTopoNearest, RandomSolids5Percent) {
    const Comparison c = compareOn(randomGrid(0.05, 1), "random 5 %");
    EXPECT_LE(c.reached + 64, c.emptyVoxels) << "the hollow box's inside is unreachable";
}

TEST(CpuTopoNearest, RandomSolids20Percent) {
    const Comparison c = compareOn(randomGrid(0.20, 2), "random 20 %");
    EXPECT_LE(c.reached + 64, c.emptyVoxels) << "the hollow box's inside is unreachable";
}

/** A 160 x 24 x 16 corridor with 2 x 2 pillars on two staggered rows; the skeleton is its middle
 *  line, left out where a pillar stands on it, plus short branches between the pillars. */
TEST(CpuTopoNearest, CorridorWithPillars) {
    Grid g(160, 24, 16);
    g.fill({0, 0, 0}, {159, 23, 15}, 0);
    g.fill({1, 1, 1}, {158, 22, 14}, 1);
    for (int x = 6; x < 154; x += 10) {
        g.fill({x, 6, 1}, {x + 1, 7, 14}, 0);
        g.fill({x + 5, 15, 1}, {x + 6, 16, 14}, 0);
        g.fill({x + 3, 11, 1}, {x + 3, 12, 14}, 0);  // thin pillars on the middle line
    }
    g.line({2, 12, 8}, {157, 12, 8});
    for (int x = 9; x < 154; x += 20)
        g.line({x, 3, 8}, {x, 20, 8});
    compareOn(g, "corridor with pillars");
}

/** Two rooms split by a one-voxel wall without a door: no label crosses the wall, in either
 *  version, and the wall stays unlabelled. */
TEST(CpuTopoNearest, WallWithoutDoor) {
    Grid g(61, 30, 30);
    g.fill({30, 0, 0}, {30, 29, 29}, 0);
    g.line({3, 3, 3}, {27, 26, 26});
    g.line({15, 2, 15}, {15, 27, 15});
    const size_t leftSeeds = g.seeds.size();
    g.line({33, 26, 3}, {57, 3, 26});
    g.line({45, 15, 2}, {45, 15, 27});
    const std::set<uint32_t> left(g.nodes.begin(), g.nodes.begin() + long(leftSeeds));
    const std::set<uint32_t> right(g.nodes.begin() + long(leftSeeds), g.nodes.end());
    const std::vector<uint32_t> fast = topo::nearestNodeGrid(g.empty, g.dims, g.seeds, g.nodes);
    const std::vector<uint32_t> exact =
        topo::nearestNodeGridExact(g.empty, g.dims, g.seeds, g.nodes);
    const Comparison c = compare(g, fast, exact);
    EXPECT_EQ(c.reached, c.emptyVoxels);
    EXPECT_LE(c.share(), 0.002);
    EXPECT_EQ(c.changed, 0u);
    for (const std::vector<uint32_t>* labels : {&fast, &exact}) {
        size_t crossed = 0, wallLabelled = 0;
        for (uint32_t z = 0; z < g.dims.nz; ++z)
            for (uint32_t y = 0; y < g.dims.ny; ++y)
                for (uint32_t x = 0; x < g.dims.nx; ++x) {
                    const uint32_t l = (*labels)[g.dims.index(x, y, z)];
                    if (x == 30)
                        wallLabelled += l != kNoNode;
                    else
                        crossed += !(x < 30 ? left : right).count(l);
                }
        EXPECT_EQ(crossed, 0u) << (labels == &fast ? "bucket" : "exact") << " version";
        EXPECT_EQ(wallLabelled, 0u);
    }
}

/** Skeleton voxels on one line along x, 3 apart: of two of them, the one nearer in x is nearer
 *  by at least sqrt 3 - sqrt 2 (every step count differs by one), so no voxel ties and both
 *  versions agree everywhere; the obstacle in a corner lengthens only paths to farther ones. */
TEST(CpuTopoNearest, ExactWithoutTies) {
    Grid g(20, 12, 10);
    for (int x = 1; x <= 19; x += 3)
        g.line({x, 5, 4}, {x, 5, 4});
    g.fill({0, 0, 0}, {2, 1, 9}, 0);
    const std::vector<uint32_t> fast = topo::nearestNodeGrid(g.empty, g.dims, g.seeds, g.nodes);
    const std::vector<uint32_t> exact =
        topo::nearestNodeGridExact(g.empty, g.dims, g.seeds, g.nodes);
    EXPECT_EQ(fast, exact);
    // Spot checks: the seed nearest in x.
    EXPECT_EQ(fast[g.at({0, 11, 9})], 0u);
    EXPECT_EQ(fast[g.at({11, 0, 0})], 3u);  // x 10 is its seed's: 1 from it, 2 from x 13
    EXPECT_EQ(fast[g.at({12, 11, 9})], 4u);
    EXPECT_EQ(fast[g.at({19, 3, 3})], 6u);
    EXPECT_EQ(fast[g.at({1, 0, 0})], kNoNode);  // solid
}

/** Several skeleton voxels of one node: labels are nodes, not voxel numbers; a voxel listed
 *  twice takes its last node, in both versions. */
TEST(CpuTopoNearest, SharedNodesAndRepeatedVoxels) {
    Grid g(24, 16, 16);
    g.seeds = {{3, 8, 8}, {4, 8, 8}, {5, 8, 8}, {20, 8, 8}, {20, 8, 8}};
    g.nodes = {7, 7, 7, 9, 11};
    const std::vector<uint32_t> fast = topo::nearestNodeGrid(g.empty, g.dims, g.seeds, g.nodes);
    const std::vector<uint32_t> exact =
        topo::nearestNodeGridExact(g.empty, g.dims, g.seeds, g.nodes);
    EXPECT_EQ(fast, exact);
    EXPECT_EQ(fast[g.at({0, 0, 0})], 7u);
    EXPECT_EQ(fast[g.at({20, 8, 8})], 11u);
    EXPECT_EQ(fast[g.at({23, 15, 15})], 11u);
    EXPECT_EQ(std::count(fast.begin(), fast.end(), 9u), 0);
}

TEST(CpuTopoNearest, Deterministic) {
    const Grid g = randomGrid(0.20, 3);
    const std::vector<uint32_t> a = topo::nearestNodeGrid(g.empty, g.dims, g.seeds, g.nodes);
    const std::vector<uint32_t> b = topo::nearestNodeGrid(g.empty, g.dims, g.seeds, g.nodes);
    EXPECT_EQ(a, b);
    // Ties go by voxel index, not by the skeleton voxels' order: the same labels in reverse.
    Grid r = g;
    std::reverse(r.seeds.begin(), r.seeds.end());
    std::reverse(r.nodes.begin(), r.nodes.end());
    EXPECT_EQ(topo::nearestNodeGrid(r.empty, r.dims, r.seeds, r.nodes), a);
}

TEST(CpuTopoNearest, NoSkeletonLeavesEverythingUnlabelled) {
    Grid g(8, 8, 8);
    const std::vector<uint32_t> fast = topo::nearestNodeGrid(g.empty, g.dims, {}, {});
    EXPECT_EQ(std::count(fast.begin(), fast.end(), kNoNode), long(g.dims.count()));
    Grid s(8, 8, 8);
    s.fill({0, 0, 0}, {7, 7, 7}, 0);
    s.seeds = {{1, 1, 1}};  // on a solid voxel: left out
    s.nodes = {0};
    const std::vector<uint32_t> solid = topo::nearestNodeGrid(s.empty, s.dims, s.seeds, s.nodes);
    EXPECT_EQ(std::count(solid.begin(), solid.end(), kNoNode), long(s.dims.count()));
}

TEST(CpuTopoNearest, BadInputsThrow) {
    Grid g(8, 8, 8);
    g.seeds = {{1, 1, 1}};
    g.nodes = {0};
    const std::vector<uint8_t> shortGrid(100, 1);
    for (auto* f : {&topo::nearestNodeGrid, &topo::nearestNodeGridExact}) {
        EXPECT_THROW(f(shortGrid, g.dims, g.seeds, g.nodes), Error);
        EXPECT_THROW(f(g.empty, g.dims, g.seeds, {}), Error);
        EXPECT_THROW(f(g.empty, g.dims, {{8, 0, 0}}, {0}), Error);
        EXPECT_THROW(f(g.empty, g.dims, {{0, -1, 0}}, {0}), Error);
    }
}

/** Timing (printed, not asserted): a 160^3 grid of random boxes, a few hundred skeleton voxels on
 *  lines. */
TEST(CpuTopoNearest, TimeOn160Cube) {
    const uint32_t n = 160;
    Grid g(n, n, n);
    std::mt19937 rng(4);
    auto coord = [&](uint32_t range) { return int(rng() % range); };
    for (int b = 0; b < 400; ++b) {
        const glm::ivec3 lo(coord(n), coord(n), coord(n));
        const glm::ivec3 size(1 + coord(12), 1 + coord(12), 1 + coord(12));
        g.fill(lo, lo + size - 1, 0);
    }
    g.randomSolids(0.03, 5);
    for (int l = 0; l < 12; ++l)
        g.line({coord(n), coord(n), coord(n)}, {coord(n), coord(n), coord(n)});
    using Clock = std::chrono::steady_clock;
    auto t0 = Clock::now();
    const std::vector<uint32_t> exact =
        topo::nearestNodeGridExact(g.empty, g.dims, g.seeds, g.nodes);
    auto t1 = Clock::now();
    const std::vector<uint32_t> fast = topo::nearestNodeGrid(g.empty, g.dims, g.seeds, g.nodes);
    auto t2 = Clock::now();
    const Comparison c = compare(g, fast, exact);
    const auto ms = [](auto d) { return std::chrono::duration<double, std::milli>(d).count(); };
    std::cout << n << "^3, " << g.seeds.size() << " skeleton voxels, " << c.emptyVoxels
              << " empty voxels (" << c.reached << " reached): exact " << ms(t1 - t0)
              << " ms, buckets " << ms(t2 - t1) << " ms, " << c.changed << " labels changed ("
              << 100.0 * c.share() << " %)\n";
    EXPECT_LE(c.share(), 0.002);
    EXPECT_EQ(c.changed, 0u);
}

}  // namespace
}  // namespace gilab
