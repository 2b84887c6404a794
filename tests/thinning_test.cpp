// Topology-preserving curve thinning (core/voxel/thinning.h): topological invariants on known
// shapes, the 26/6 simple-point test on hand-built neighbourhoods, and thinning that keeps
// components, cavities and Euler characteristic while leaving nothing removable.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <vector>

#include <tbb/global_control.h>

#include "core/util/error.h"
#include "core/voxel/distance_transform.h"
#include "core/voxel/thinning.h"

namespace gilab {
namespace {

// ---------------------------------------------------------------------------------------------
// Shape builders
// ---------------------------------------------------------------------------------------------

struct Grid {
    GridDims dims;
    std::vector<uint8_t> v;

    Grid(uint32_t nx, uint32_t ny, uint32_t nz) : dims{nx, ny, nz}, v(size_t(nx) * ny * nz, 0) {}
    size_t index(int x, int y, int z) const { return x + dims.nx * (y + size_t(dims.ny) * z); }
    bool inside(int x, int y, int z) const {
        return x >= 0 && y >= 0 && z >= 0 && x < int(dims.nx) && y < int(dims.ny) &&
               z < int(dims.nz);
    }
    uint8_t at(int x, int y, int z) const { return inside(x, y, z) ? v[index(x, y, z)] : 0; }
    void set(int x, int y, int z, uint8_t value = 1) { v[index(x, y, z)] = value; }
    void box(int x0, int y0, int z0, int x1, int y1, int z1, uint8_t value = 1) {  // [x0, x1)
        for (int z = z0; z < z1; ++z) {
            for (int y = y0; y < y1; ++y) {
                for (int x = x0; x < x1; ++x)
                    set(x, y, z, value);
            }
        }
    }
    /** Sets every voxel whose centre satisfies inside(x, y, z) (voxel-centre coordinates). */
    template <class F>
    void fill(F inside) {
        for (int z = 0; z < int(dims.nz); ++z) {
            for (int y = 0; y < int(dims.ny); ++y) {
                for (int x = 0; x < int(dims.nx); ++x) {
                    if (inside(double(x), double(y), double(z))) set(x, y, z);
                }
            }
        }
    }
    size_t count() const {
        size_t n = 0;
        for (uint8_t b : v)
            n += b != 0;
        return n;
    }
    int neighbourCount(int x, int y, int z) const {
        int n = 0;
        for (int dz = -1; dz <= 1; ++dz) {
            for (int dy = -1; dy <= 1; ++dy) {
                for (int dx = -1; dx <= 1; ++dx) {
                    if (dx != 0 || dy != 0 || dz != 0) n += at(x + dx, y + dy, z + dz) != 0;
                }
            }
        }
        return n;
    }
};

Grid makeBall(uint32_t n, double radius) {
    Grid g(n, n, n);
    const double c = (n - 1) / 2.0;
    g.fill([&](double x, double y, double z) {
        return (x - c) * (x - c) + (y - c) * (y - c) + (z - c) * (z - c) <= radius * radius;
    });
    return g;
}

Grid makeShell(uint32_t n, double inner, double outer) {
    Grid g(n, n, n);
    const double c = (n - 1) / 2.0;
    g.fill([&](double x, double y, double z) {
        const double r2 = (x - c) * (x - c) + (y - c) * (y - c) + (z - c) * (z - c);
        return r2 <= outer * outer && r2 > inner * inner;
    });
    return g;
}

/** Solid torus around the z axis: ring radius R, tube radius r. */
Grid makeTorus(uint32_t n, uint32_t nz, double ringRadius, double tubeRadius) {
    Grid g(n, n, nz);
    const double c = (n - 1) / 2.0, cz = (nz - 1) / 2.0;
    g.fill([&](double x, double y, double z) {
        const double q = std::hypot(x - c, y - c) - ringRadius;
        return q * q + (z - cz) * (z - cz) <= tubeRadius * tubeRadius;
    });
    return g;
}

/** Union of random balls; mt19937 raw outputs so the shape is the same on every platform. */
Grid makeBlobs(uint32_t n, uint32_t ballCount, uint32_t seed) {
    Grid g(n, n, n);
    std::mt19937 rng(seed);
    const double rMin = n / 16.0, rMax = n / 6.0;
    for (uint32_t b = 0; b < ballCount; ++b) {
        const double cx = rng() % n, cy = rng() % n, cz = rng() % n;
        const double r = rMin + (rMax - rMin) * (rng() % 1000) / 1000.0;
        g.fill([&](double x, double y, double z) {
            return (x - cx) * (x - cx) + (y - cy) * (y - cy) + (z - cz) * (z - cz) <= r * r;
        });
    }
    return g;
}

void expectSameTopology(const Topology& a, const Topology& b) {
    EXPECT_EQ(a.components, b.components);
    EXPECT_EQ(a.cavities, b.cavities);
    EXPECT_EQ(a.euler, b.euler);
}

/** Curve end (thinning.h): one object 26-neighbour, which has two. Implies the plain end point. */
bool isCurveEnd(const Grid& g, int x, int y, int z) {
    if (g.neighbourCount(x, y, z) != 1) return false;
    for (int dz = -1; dz <= 1; ++dz) {
        for (int dy = -1; dy <= 1; ++dy) {
            for (int dx = -1; dx <= 1; ++dx) {
                if ((dx != 0 || dy != 0 || dz != 0) && g.at(x + dx, y + dy, z + dz) != 0) {
                    return g.neighbourCount(x + dx, y + dy, z + dz) == 2;
                }
            }
        }
    }
    return false;
}

/** Counts voxels that could still be removed (simple and not a curve end): 0 when thin. */
size_t countRemovable(const Grid& g) {
    size_t removable = 0;
    for (int z = 0; z < int(g.dims.nz); ++z) {
        for (int y = 0; y < int(g.dims.ny); ++y) {
            for (int x = 0; x < int(g.dims.nx); ++x) {
                if (g.at(x, y, z) == 0 || isCurveEnd(g, x, y, z)) continue;
                removable += isSimplePoint(g.v, g.dims, x, y, z);
            }
        }
    }
    return removable;
}

/** Thins g and checks topology is kept, nothing removable is left and the stats add up. */
Topology thinAndCheck(Grid& g) {
    const Topology before = computeTopology(g.v, g.dims);
    const size_t countBefore = g.count();
    const ThinningStats stats = thinCurveSkeleton(g.v, g.dims);
    const Topology after = computeTopology(g.v, g.dims);
    expectSameTopology(before, after);
    EXPECT_EQ(countRemovable(g), 0u);
    EXPECT_EQ(stats.removed, countBefore - g.count());
    EXPECT_GE(stats.iterations, 2u);  // at least one pass per phase
    return after;
}

// ---------------------------------------------------------------------------------------------
// computeTopology
// ---------------------------------------------------------------------------------------------

TEST(CpuThinning, TopologyOfKnownShapes) {
    Grid single(3, 3, 3);
    single.set(1, 1, 1);
    Topology t = computeTopology(single.v, single.dims);
    EXPECT_EQ(t.components, 1u);
    EXPECT_EQ(t.cavities, 0u);
    EXPECT_EQ(t.euler, 1);

    const Grid ball = makeBall(17, 6.5);
    t = computeTopology(ball.v, ball.dims);
    EXPECT_EQ(t.components, 1u);
    EXPECT_EQ(t.cavities, 0u);
    EXPECT_EQ(t.euler, 1);

    const Grid shell = makeShell(21, 5.0, 8.5);
    t = computeTopology(shell.v, shell.dims);
    EXPECT_EQ(t.components, 1u);
    EXPECT_EQ(t.cavities, 1u);
    EXPECT_EQ(t.euler, 2);

    const Grid torus = makeTorus(28, 10, 8.0, 3.2);
    t = computeTopology(torus.v, torus.dims);
    EXPECT_EQ(t.components, 1u);
    EXPECT_EQ(t.cavities, 0u);
    EXPECT_EQ(t.euler, 0);  // one tunnel

    Grid blocks(12, 6, 6);
    blocks.box(1, 1, 1, 4, 5, 5);
    blocks.box(6, 1, 1, 11, 4, 3);
    t = computeTopology(blocks.v, blocks.dims);
    EXPECT_EQ(t.components, 2u);
    EXPECT_EQ(t.cavities, 0u);
    EXPECT_EQ(t.euler, 2);
}

TEST(CpuThinning, TopologyCountsDiagonalContactsAndHoles) {
    // Two voxels sharing only a corner: one 26-component (and the cube union is connected).
    Grid corner(2, 2, 2);
    corner.set(0, 0, 0);
    corner.set(1, 1, 1);
    Topology t = computeTopology(corner.v, corner.dims);
    EXPECT_EQ(t.components, 1u);
    EXPECT_EQ(t.euler, 1);

    // A block with two through holes: euler = 1 - 2 tunnels; a block with a cavity: euler 2.
    Grid holes(14, 8, 6);
    holes.box(0, 0, 0, 14, 8, 6);
    holes.box(3, 3, 0, 5, 5, 6, 0);
    holes.box(9, 3, 0, 11, 5, 6, 0);
    t = computeTopology(holes.v, holes.dims);
    EXPECT_EQ(t.components, 1u);
    EXPECT_EQ(t.cavities, 0u);
    EXPECT_EQ(t.euler, -1);

    Grid cavity(10, 10, 10);
    cavity.box(0, 0, 0, 10, 10, 10);
    cavity.box(4, 4, 4, 6, 6, 6, 0);
    t = computeTopology(cavity.v, cavity.dims);
    EXPECT_EQ(t.components, 1u);
    EXPECT_EQ(t.cavities, 1u);
    EXPECT_EQ(t.euler, 2);
}

// ---------------------------------------------------------------------------------------------
// isSimplePoint (26/6) on hand-built 3x3x3 neighbourhoods
// ---------------------------------------------------------------------------------------------

TEST(CpuThinning, SimplePointOnHandBuiltNeighbourhoods) {
    Grid g(3, 3, 3);
    g.set(1, 1, 1);
    EXPECT_FALSE(isSimplePoint(g.v, g.dims, 1, 1, 1));  // isolated: T26 = 0

    Grid line(3, 3, 3);
    line.box(0, 1, 1, 3, 2, 2);
    EXPECT_FALSE(isSimplePoint(line.v, line.dims, 1, 1, 1));  // splits the line: T26 = 2
    EXPECT_TRUE(isSimplePoint(line.v, line.dims, 0, 1, 1));   // line end: T26 = 1, T6 = 1

    Grid cube(3, 3, 3);
    cube.box(0, 0, 0, 3, 3, 3);
    EXPECT_TRUE(isSimplePoint(cube.v, cube.dims, 0, 0, 0));   // corner of a full cube
    EXPECT_TRUE(isSimplePoint(cube.v, cube.dims, 1, 0, 0));   // edge middle
    EXPECT_FALSE(isSimplePoint(cube.v, cube.dims, 1, 1, 1));  // interior: T6 = 0 (cavity)

    Grid plate(3, 3, 3);
    plate.box(0, 0, 1, 3, 3, 2);
    EXPECT_FALSE(isSimplePoint(plate.v, plate.dims, 1, 1, 1));  // punches a tunnel: T6 = 2
    EXPECT_TRUE(isSimplePoint(plate.v, plate.dims, 1, 0, 1));   // plate edge

    // Ring of 8 around the centre of a plane: the centre would close the tunnel (T26 = 1 but
    // T6 = 2 with the centre, as the ring is then filled); the ring voxels are not simple.
    Grid ring(3, 3, 3);
    ring.box(0, 0, 1, 3, 3, 2);
    ring.set(1, 1, 1, 0);
    EXPECT_FALSE(isSimplePoint(ring.v, ring.dims, 1, 1, 1));
    EXPECT_FALSE(isSimplePoint(ring.v, ring.dims, 1, 0, 1));
    // A voxel whose two object neighbours touch diagonally: removing it keeps them connected.
    Grid bend(3, 3, 3);
    bend.set(0, 1, 1);
    bend.set(1, 1, 1);
    bend.set(1, 2, 1);
    EXPECT_TRUE(isSimplePoint(bend.v, bend.dims, 1, 1, 1));
}

TEST(CpuThinning, SimplePointAgreesWithGlobalInvariants) {
    // In a 3x3x3 grid (outside = background) local and global topology coincide, so p is simple
    // iff deleting it keeps components, cavities and Euler characteristic: an independent check of
    // the topological numbers against the cube-complex count of computeTopology.
    std::mt19937 rng(5);
    const GridDims dims{3, 3, 3};
    size_t simpleCount = 0;
    for (int trial = 0; trial < 20000; ++trial) {
        std::vector<uint8_t> v(27);
        const uint32_t densityPercent = rng() % 100;
        for (uint8_t& b : v)
            b = rng() % 100 < densityPercent;
        v[13] = 1;
        const bool simple = isSimplePoint(v, dims, 1, 1, 1);
        const Topology with = computeTopology(v, dims);
        v[13] = 0;
        const Topology without = computeTopology(v, dims);
        const bool same = with.components == without.components &&
                          with.cavities == without.cavities && with.euler == without.euler;
        ASSERT_EQ(simple, same) << "trial " << trial;
        simpleCount += simple;
    }
    EXPECT_GT(simpleCount, 2000u);  // both outcomes well sampled
    EXPECT_LT(simpleCount, 18000u);
}

// ---------------------------------------------------------------------------------------------
// Thinning keeps topology and leaves nothing removable
// ---------------------------------------------------------------------------------------------

TEST(CpuThinning, SolidBallKeepsTopology) {
    Grid g = makeBall(21, 8.5);
    const Topology t = thinAndCheck(g);
    EXPECT_EQ(t.components, 1u);
    EXPECT_EQ(t.euler, 1);
    EXPECT_GE(g.count(), 1u);
    EXPECT_LE(g.count(), 40u);  // a point or a short curve, not a surface
}

TEST(CpuThinning, SolidTorusThinsToClosedRing) {
    // Tube radius 5 left 1-voxel spurs under the plain one-neighbour end point rule.
    for (const double tubeRadius : {3.0, 4.0, 5.0}) {
        SCOPED_TRACE("tube radius " + std::to_string(tubeRadius));
        Grid g = makeTorus(36, 14, 11.0, tubeRadius);
        const Topology t = thinAndCheck(g);
        EXPECT_EQ(t.components, 1u);
        EXPECT_EQ(t.euler, 0);
        // A closed curve: every voxel has exactly 2 object 26-neighbours; 2 pi 11 = 69 along the
        // Euclidean ring, fewer 26-steps (a diagonal step covers sqrt 2).
        size_t notTwo = 0;
        for (int z = 0; z < 14; ++z) {
            for (int y = 0; y < 36; ++y) {
                for (int x = 0; x < 36; ++x) {
                    if (g.at(x, y, z) != 0 && g.neighbourCount(x, y, z) != 2) ++notTwo;
                }
            }
        }
        EXPECT_EQ(notTwo, 0u);
        EXPECT_GE(g.count(), 45u);
        EXPECT_LE(g.count(), 75u);
    }
}

TEST(CpuThinning, HollowShellKeepsItsCavity) {
    Grid g = makeShell(23, 5.0, 9.5);
    const Topology t = thinAndCheck(g);
    EXPECT_EQ(t.cavities, 1u);
    EXPECT_EQ(t.euler, 2);
}

TEST(CpuThinning, TwoHoledSolidKeepsBothTunnels) {
    Grid g(22, 14, 10);
    g.box(1, 1, 1, 21, 13, 9);
    g.box(5, 5, 0, 8, 9, 10, 0);
    g.box(14, 5, 0, 17, 9, 10, 0);
    const Topology t = thinAndCheck(g);
    EXPECT_EQ(t.components, 1u);
    EXPECT_EQ(t.components + t.cavities - t.euler, 2);  // two tunnels
}

TEST(CpuThinning, BlockWithCavityKeepsIt) {
    Grid g(16, 16, 16);
    g.box(1, 1, 1, 15, 15, 15);
    g.box(6, 6, 6, 10, 10, 10, 0);
    const Topology t = thinAndCheck(g);
    EXPECT_EQ(t.cavities, 1u);
    EXPECT_EQ(t.euler, 2);
}

TEST(CpuThinning, RandomBlobsKeepTopology) {
    for (uint32_t seed : {1u, 2u, 3u, 4u, 5u, 6u}) {
        SCOPED_TRACE("seed " + std::to_string(seed));
        Grid g = makeBlobs(32, 10, seed);
        thinAndCheck(g);
    }
}

TEST(CpuThinning, RandomNoiseKeepsTopology) {
    // Voxel noise: many components, cavities and tunnels, most voxels on a border.
    for (const uint32_t densityPercent : {15u, 35u, 55u, 75u}) {
        SCOPED_TRACE("density " + std::to_string(densityPercent));
        Grid g(18, 18, 18);
        std::mt19937 rng(densityPercent);
        for (uint8_t& b : g.v)
            b = rng() % 100 < densityPercent;
        thinAndCheck(g);
    }
}

TEST(CpuThinning, ObjectTouchingTheGridBorder) {
    // Outside the grid is background: a full grid is one block and thins like one.
    Grid g(9, 7, 5);
    g.box(0, 0, 0, 9, 7, 5);
    const Topology t = thinAndCheck(g);
    EXPECT_EQ(t.components, 1u);
    EXPECT_EQ(t.euler, 1);
}

// ---------------------------------------------------------------------------------------------
// Even thickness: what parallel thinning without a sequential re-check deletes entirely
// ---------------------------------------------------------------------------------------------

TEST(CpuThinning, EvenThicknessObjectsDoNotVanish) {
    // Two voxels touching at a corner: both simple, neither a curve end, both U-border and past
    // the opposite-neighbour rule; deleting both without the re-check would erase the component.
    Grid pair(4, 4, 3);
    pair.set(1, 1, 1);
    pair.set(2, 2, 1);
    Grid cube(4, 4, 4);
    cube.box(1, 1, 1, 3, 3, 3);
    Grid slab(24, 24, 4);
    slab.box(2, 2, 1, 22, 22, 3);  // 20x20x2
    Grid thickSlab(20, 20, 6);
    thickSlab.box(1, 1, 1, 19, 19, 5);  // 18x18x4
    for (Grid* g : {&pair, &cube, &slab, &thickSlab}) {
        const Topology t = thinAndCheck(*g);
        EXPECT_EQ(t.components, 1u);
        EXPECT_GE(g->count(), 1u);
    }
    EXPECT_EQ(pair.count(), 1u);
}

TEST(CpuThinning, TwoByTwoBarThinsToCurveOfItsLength) {
    Grid g(4, 4, 32);
    g.box(1, 1, 1, 3, 3, 31);  // 2x2x30
    const Topology t = thinAndCheck(g);
    EXPECT_EQ(t.components, 1u);
    EXPECT_GE(g.count(), 26u);
    EXPECT_LE(g.count(), 30u);
    size_t endpoints = 0, branch = 0;
    for (int z = 0; z < 32; ++z) {
        for (int y = 0; y < 4; ++y) {
            for (int x = 0; x < 4; ++x) {
                if (g.at(x, y, z) == 0) continue;
                const int n = g.neighbourCount(x, y, z);
                endpoints += n == 1;
                branch += n > 2;
            }
        }
    }
    EXPECT_EQ(endpoints, 2u);
    EXPECT_EQ(branch, 0u);
}

TEST(CpuThinning, BoxRoomInteriorThinsToSomething) {
    // The empty inside of a closed box with 1-voxel walls, as the VPL technique thins it.
    Grid walls(26, 18, 14);
    walls.box(0, 0, 0, 26, 18, 14);
    walls.box(1, 1, 1, 25, 17, 13, 0);
    Grid room(26, 18, 14);
    for (size_t i = 0; i < room.v.size(); ++i)
        room.v[i] = walls.v[i] == 0;
    const Topology t = thinAndCheck(room);
    EXPECT_EQ(t.components, 1u);
    EXPECT_GE(room.count(), 1u);
    EXPECT_LT(room.count(), 60u);
}

// ---------------------------------------------------------------------------------------------
// Determinism, bad input, timing
// ---------------------------------------------------------------------------------------------

TEST(CpuThinning, DeterministicAcrossRunsAndThreadCounts) {
    const Grid g = makeBlobs(40, 12, 7);
    Grid a = g, b = g, c = g;
    const ThinningStats sa = thinCurveSkeleton(a.v, a.dims);
    const ThinningStats sb = thinCurveSkeleton(b.v, b.dims);
    {
        tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
        thinCurveSkeleton(c.v, c.dims);
    }
    EXPECT_EQ(a.v, b.v);
    EXPECT_EQ(a.v, c.v);
    EXPECT_EQ(sa.removed, sb.removed);
    EXPECT_EQ(sa.iterations, sb.iterations);
}

TEST(CpuThinning, BadInputThrows) {
    std::vector<uint8_t> v(10, 1);
    EXPECT_THROW(thinCurveSkeleton(v, GridDims{2, 2, 2}), Error);  // 10 != 8
    EXPECT_THROW(thinCurveSkeleton(v, GridDims{10, 1, 0}), Error);
    EXPECT_THROW(computeTopology(v, GridDims{0, 10, 1}), Error);
    EXPECT_THROW(isSimplePoint(v, GridDims{10, 1, 1}, 10, 0, 0), Error);
    EXPECT_THROW(isSimplePoint(v, GridDims{5, 1, 1}, 0, 0, 0), Error);
    try {
        thinCurveSkeleton(v, GridDims{3, 3, 3});
        FAIL() << "expected gilab::Error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("3x3x3"), std::string::npos) << e.what();
    }
    EXPECT_EQ(v, std::vector<uint8_t>(10, 1));  // untouched on error
}

TEST(CpuThinning, LargeBlobGridTimed) {
    Grid g = makeBlobs(96, 40, 11);
    const Topology before = computeTopology(g.v, g.dims);
    const size_t countBefore = g.count();
    const auto t0 = std::chrono::steady_clock::now();
    const ThinningStats stats = thinCurveSkeleton(g.v, g.dims);
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    std::printf("[thinning] 96^3: %zu -> %zu voxels, %u passes, %.1f ms\n", countBefore, g.count(),
                stats.iterations, ms);
    expectSameTopology(before, computeTopology(g.v, g.dims));
}

// ---------------------------------------------------------------------------------------------
// Lifespan filter (ThinningOptions): chessboard distance and opening of the empty space
// ---------------------------------------------------------------------------------------------

/** Curve statistics: tips (at most one object 26-neighbour), junctions (three or more), voxels
 *  and the extent along x. */
struct CurveCounts {
    size_t ends = 0, junctions = 0, voxels = 0;
    int minX = std::numeric_limits<int>::max(), maxX = -1;
};

CurveCounts countCurve(const Grid& g) {
    CurveCounts c;
    for (int z = 0; z < int(g.dims.nz); ++z) {
        for (int y = 0; y < int(g.dims.ny); ++y) {
            for (int x = 0; x < int(g.dims.nx); ++x) {
                if (g.at(x, y, z) == 0) continue;
                const int n = g.neighbourCount(x, y, z);
                c.ends += n <= 1;
                c.junctions += n >= 3;
                ++c.voxels;
                c.minX = std::min(c.minX, x);
                c.maxX = std::max(c.maxX, x);
            }
        }
    }
    return c;
}

/** The empty space of a solid grid with its chessboard distance to the solid and its opening. */
struct EmptySpace {
    Grid empty;
    std::vector<uint32_t> distance, opening;

    explicit EmptySpace(const Grid& solid) : empty(solid.dims.nx, solid.dims.ny, solid.dims.nz) {
        for (size_t i = 0; i < solid.v.size(); ++i)
            empty.v[i] = solid.v[i] == 0;
        distance = chessboardDistanceTransform(solid.v, solid.dims);
        opening = chessboardOpening(distance, solid.dims);
    }
    ThinningOptions options() const { return ThinningOptions{&distance, &opening}; }
};

/** The complement of an object grid (its solid, for EmptySpace). */
Grid complement(const Grid& g) {
    Grid c(g.dims.nx, g.dims.ny, g.dims.nz);
    for (size_t i = 0; i < g.v.size(); ++i)
        c.v[i] = g.v[i] == 0;
    return c;
}

/** The empty space of `solid` thinned without and with the lifespan filter; both keep the
 *  topology, the plain one leaves nothing removable, the filtered one nothing simple but curve
 *  voxels (anchored voxels were born with at most two neighbours, and thinning only deletes). */
struct LifespanRun {
    Grid plain, filtered;
    ThinningStats plainStats, filteredStats;
    CurveCounts plainCurve, filteredCurve;
};

LifespanRun thinBothWays(const Grid& solid) {
    const EmptySpace space(solid);
    LifespanRun run{space.empty, space.empty, {}, {}, {}, {}};
    const Topology before = computeTopology(space.empty.v, space.empty.dims);
    run.plainStats = thinCurveSkeleton(run.plain.v, run.plain.dims);
    run.filteredStats = thinCurveSkeleton(run.filtered.v, run.filtered.dims, space.options());
    {
        SCOPED_TRACE("plain");
        expectSameTopology(before, computeTopology(run.plain.v, run.plain.dims));
        EXPECT_EQ(countRemovable(run.plain), 0u);
        EXPECT_EQ(run.plainStats.anchored, 0u);
    }
    {
        SCOPED_TRACE("lifespan");
        const Grid& g = run.filtered;
        expectSameTopology(before, computeTopology(g.v, g.dims));
        EXPECT_EQ(run.filteredStats.removed, space.empty.count() - g.count());
        size_t simple = 0, simpleThick = 0;
        for (int z = 0; z < int(g.dims.nz); ++z) {
            for (int y = 0; y < int(g.dims.ny); ++y) {
                for (int x = 0; x < int(g.dims.nx); ++x) {
                    if (g.at(x, y, z) == 0 || !isSimplePoint(g.v, g.dims, x, y, z)) continue;
                    ++simple;
                    simpleThick += g.neighbourCount(x, y, z) > 2;
                }
            }
        }
        EXPECT_EQ(simpleThick, 0u);                     // simple voxels left are all anchored
        EXPECT_GE(run.filteredStats.anchored, simple);  // ... and counted
        EXPECT_LE(run.filteredStats.anchored, g.count());
    }
    run.plainCurve = countCurve(run.plain);
    run.filteredCurve = countCurve(run.filtered);
    return run;
}

/** Solid grid: a 40x24x24 empty room inside a 1-voxel solid frame. */
Grid makeRoomSolid() {
    Grid solid(42, 26, 26);
    solid.box(0, 0, 0, 42, 26, 26);
    solid.box(1, 1, 1, 41, 25, 25, 0);
    return solid;
}

/** Solid grid: a corridor 100 long, width x width across, inside a solid frame (2 at the ends). */
Grid makeCorridorSolid(int width) {
    Grid solid(104, width + 2, width + 2);
    solid.box(0, 0, 0, 104, width + 2, width + 2);
    solid.box(2, 1, 1, 102, width + 1, width + 1, 0);
    return solid;
}

TEST(CpuThinningLifespan, RemovesSpursTowardSmallBumps) {
    const Grid room = makeRoomSolid();
    Grid bumps3 = room;  // 3x3x2 bumps on the floor, the ceiling and a side wall
    bumps3.box(10, 1, 10, 13, 3, 13);
    bumps3.box(28, 23, 12, 31, 25, 15);
    bumps3.box(20, 12, 1, 23, 15, 3);
    Grid bumps2 = room;  // 2x2x1 bumps
    bumps2.box(10, 1, 10, 12, 2, 12);
    bumps2.box(28, 24, 12, 30, 25, 14);
    bumps2.box(20, 12, 1, 22, 14, 2);
    for (const Grid* solid : {&bumps3, &bumps2}) {
        SCOPED_TRACE(solid == &bumps3 ? "3x3x2 bumps" : "2x2x1 bumps");
        const LifespanRun run = thinBothWays(*solid);
        const CurveCounts& plain = run.plainCurve;
        const CurveCounts& filtered = run.filteredCurve;
        std::printf(
            "[thinning] room with bumps: plain %zu voxels, %zu ends, %zu junctions; "
            "lifespan %zu voxels, %zu ends, %zu junctions, %llu anchored\n",
            plain.voxels, plain.ends, plain.junctions, filtered.voxels, filtered.ends,
            filtered.junctions, (unsigned long long)run.filteredStats.anchored);
        // Plain curve-end thinning keeps spurs toward the bumps: a tree with many tips.
        EXPECT_GE(plain.ends, 6u);
        EXPECT_GE(plain.junctions, 4u);
        // The filter erodes them: one curve along the room, as in the room without bumps.
        EXPECT_LT(filtered.ends, plain.ends);
        EXPECT_EQ(filtered.ends, 2u);
        EXPECT_EQ(filtered.junctions, 0u);
        EXPECT_LT(filtered.voxels, plain.voxels / 2);
        EXPECT_GE(filtered.voxels, 12u);
        EXPECT_GE(filtered.maxX - filtered.minX, 12);  // along the room's long axis (x)
        EXPECT_GT(run.filteredStats.anchored, 0u);
    }
    // Without bumps both give the room's central line along x.
    const LifespanRun run = thinBothWays(room);
    EXPECT_EQ(run.plainCurve.ends, 2u);
    EXPECT_EQ(run.filteredCurve.ends, 2u);
    EXPECT_EQ(run.filteredCurve.junctions, 0u);
    EXPECT_GE(run.filteredCurve.voxels + 4, run.plainCurve.voxels);
}

TEST(CpuThinningLifespan, RingCorridorKeepsItsTunnel) {
    // The empty space is a solid torus (a ring corridor): its tunnel survives the filter.
    for (const double tubeRadius : {3.0, 4.5, 6.0}) {
        SCOPED_TRACE("tube radius " + std::to_string(tubeRadius));
        const Grid ring = makeTorus(44, 18, 13.0, tubeRadius);
        const LifespanRun run = thinBothWays(complement(ring));
        const Grid& g = run.filtered;
        const Topology t = computeTopology(g.v, g.dims);
        EXPECT_EQ(t.components, 1u);
        EXPECT_EQ(t.euler, 0);      // one tunnel
        EXPECT_GE(g.count(), 55u);  // 2 pi 13 = 82 along the ring, fewer 26-steps
        EXPECT_LE(g.count(), 100u);
        if (tubeRadius > 5.0) continue;  // see below
        // A thin ring is a closed curve with nothing to erode, every voxel anchored. (The
        // chessboard maximal balls of a wide round tube form a cross in its section, so the
        // rule keeps short branches along the axes there, as it should by opening == distance.)
        size_t notTwo = 0;
        for (int z = 0; z < int(g.dims.nz); ++z) {
            for (int y = 0; y < int(g.dims.ny); ++y) {
                for (int x = 0; x < int(g.dims.nx); ++x) {
                    if (g.at(x, y, z) != 0 && g.neighbourCount(x, y, z) != 2) ++notTwo;
                }
            }
        }
        EXPECT_EQ(notTwo, 0u);
        EXPECT_EQ(run.filteredStats.anchored, g.count());
    }
}

TEST(CpuThinningLifespan, KeepsTheMainSkeletonOfALongCorridor) {
    for (const int width : {6, 8, 10}) {
        SCOPED_TRACE("width " + std::to_string(width));
        const LifespanRun run = thinBothWays(makeCorridorSolid(width));
        const CurveCounts& c = run.filteredCurve;
        EXPECT_EQ(c.ends, 2u);
        EXPECT_EQ(c.junctions, 0u);
        EXPECT_GT(c.maxX - c.minX + 1, 80);  // of the corridor's 100
        EXPECT_GT(c.voxels, 80u);
        EXPECT_EQ(run.filteredStats.anchored, c.voxels);  // centres of their maximal balls
    }
    // With bumps on its walls the main line still runs the corridor's length.
    Grid bumpy = makeCorridorSolid(10);
    for (int x = 15; x < 100; x += 20) {
        bumpy.box(x, 1, 2, x + 2, 2, 4);
        bumpy.box(x + 8, 10, 7, x + 10, 11, 9);
    }
    const LifespanRun run = thinBothWays(bumpy);
    EXPECT_GT(run.filteredCurve.maxX - run.filteredCurve.minX + 1, 80);
    EXPECT_LT(run.filteredCurve.ends, run.plainCurve.ends);
    EXPECT_EQ(computeTopology(run.filtered.v, run.filtered.dims).components, 1u);
}

TEST(CpuThinningLifespan, RandomShapesKeepTopology) {
    // The empty space around random blobs (cavities, tunnels, surfaces) and voxel noise.
    for (const uint32_t seed : {1u, 2u, 3u}) {
        SCOPED_TRACE("blobs seed " + std::to_string(seed));
        Grid solid = makeBlobs(36, 10, seed);
        solid.box(0, 0, 0, 36, 36, 1);
        solid.box(0, 0, 0, 36, 1, 36);
        solid.box(0, 0, 0, 1, 36, 36);
        thinBothWays(solid);
    }
    for (const uint32_t densityPercent : {25u, 60u}) {
        SCOPED_TRACE("noise " + std::to_string(densityPercent));
        Grid solid(18, 18, 18);
        std::mt19937 rng(100 + densityPercent);
        for (uint8_t& b : solid.v)
            b = rng() % 100 >= densityPercent;
        thinBothWays(solid);
    }
    // No solid voxel at all: distance and opening are kNoFeatureChessboard, slack 0.
    thinBothWays(Grid(9, 7, 5));
}

TEST(CpuThinningLifespan, DeterministicAcrossThreadCounts) {
    Grid blobs = makeBlobs(40, 12, 2);
    blobs.box(0, 0, 0, 40, 40, 1);
    Grid room = makeRoomSolid();
    room.box(10, 1, 10, 13, 3, 13);
    room.box(20, 12, 1, 23, 15, 3);
    for (const Grid* solid : {&blobs, &room}) {
        const EmptySpace space(*solid);
        Grid a = space.empty, b = space.empty, c = space.empty;
        const ThinningStats sa = thinCurveSkeleton(a.v, a.dims, space.options());
        ThinningStats sb, sc;
        {
            tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
            sb = thinCurveSkeleton(b.v, b.dims, space.options());
        }
        {
            tbb::global_control two(tbb::global_control::max_allowed_parallelism, 2);
            sc = thinCurveSkeleton(c.v, c.dims, space.options());
        }
        EXPECT_EQ(a.v, b.v);
        EXPECT_EQ(a.v, c.v);
        for (const ThinningStats* s : {&sb, &sc}) {
            EXPECT_EQ(sa.iterations, s->iterations);
            EXPECT_EQ(sa.removed, s->removed);
            EXPECT_EQ(sa.anchored, s->anchored);
        }
        EXPECT_GT(sa.anchored, 0u);
    }
}

TEST(CpuThinningLifespan, OptionsOffIsThePlainThinning) {
    Grid room = makeRoomSolid();
    room.box(10, 1, 10, 13, 3, 13);
    for (const Grid& object : {makeBlobs(40, 12, 7), complement(room)}) {
        Grid a = object, b = object;
        const ThinningStats sa = thinCurveSkeleton(a.v, a.dims);
        const ThinningStats sb = thinCurveSkeleton(b.v, b.dims, ThinningOptions{});
        EXPECT_EQ(a.v, b.v);
        EXPECT_EQ(sa.iterations, sb.iterations);
        EXPECT_EQ(sa.removed, sb.removed);
        EXPECT_EQ(sb.anchored, 0u);
    }
}

TEST(CpuThinningLifespan, BadOptionsThrow) {
    const GridDims dims{3, 3, 3};
    std::vector<uint8_t> v(27, 1);
    const std::vector<uint32_t> good(27, 1), shortMap(26, 1);
    const auto expectThrows = [&](const ThinningOptions& options, const std::string& needle) {
        try {
            thinCurveSkeleton(v, dims, options);
            ADD_FAILURE() << "no throw for " << needle;
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
        }
    };
    expectThrows({&good, nullptr}, "got only distance");
    expectThrows({nullptr, &good}, "got only opening");
    expectThrows({&shortMap, &good}, "distance has 26 values, the object 27");
    expectThrows({&good, &shortMap}, "opening has 26 values, the object 27");
    EXPECT_EQ(v, std::vector<uint8_t>(27, 1));  // untouched on error
}

TEST(CpuThinningLifespan, LargeRoomTimed) {
    // A 96^3 empty room with bumps, as the VPL technique thins a scene's empty space.
    Grid solid(96, 96, 96);
    solid.box(0, 0, 0, 96, 96, 96);
    solid.box(1, 1, 1, 95, 95, 95, 0);
    std::mt19937 rng(3);
    for (int b = 0; b < 12; ++b) {
        const int x = 5 + rng() % 80, y = 5 + rng() % 80, z = 1 + rng() % 3;
        solid.box(x, y, 1, x + 4, y + 4, 1 + z);
    }
    const EmptySpace space(solid);
    Grid a = space.empty, b = space.empty;
    const auto t0 = std::chrono::steady_clock::now();
    const ThinningStats sa = thinCurveSkeleton(a.v, a.dims);
    const auto t1 = std::chrono::steady_clock::now();
    const ThinningStats sb = thinCurveSkeleton(b.v, b.dims, space.options());
    const auto t2 = std::chrono::steady_clock::now();
    const CurveCounts ca = countCurve(a), cb = countCurve(b);
    std::printf(
        "[thinning] 96^3 room: plain %zu voxels %zu ends, %u passes, %.1f ms; lifespan "
        "%zu voxels %zu ends, %u passes, %.1f ms\n",
        ca.voxels, ca.ends, sa.iterations,
        std::chrono::duration<double, std::milli>(t1 - t0).count(), cb.voxels, cb.ends,
        sb.iterations, std::chrono::duration<double, std::milli>(t2 - t1).count());
    EXPECT_LE(cb.ends, ca.ends);
    expectSameTopology(computeTopology(a.v, a.dims), computeTopology(b.v, b.dims));
}

}  // namespace
}  // namespace gilab
