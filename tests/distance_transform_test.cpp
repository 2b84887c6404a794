// core/voxel: exact Euclidean distance transform against brute force. No GPU needed.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "core/util/error.h"
#include "core/voxel/distance_transform.h"

using namespace gilab;

namespace {

/** Random feature grid with the given density, fixed by seed. */
std::vector<uint8_t> randomFeatures(const GridDims& dims, double density, uint32_t seed) {
    std::mt19937 rng(seed);
    std::bernoulli_distribution coin(density);
    std::vector<uint8_t> feature(dims.count());
    for (uint8_t& f : feature)
        f = coin(rng) ? 1 : 0;
    return feature;
}

/** O(n^2) squared distance at (x, y, z) to the nearest feature, kNoFeatureDistance if none. */
float bruteForceAt(const std::vector<uint8_t>& feature, const GridDims& dims, int64_t x, int64_t y,
                   int64_t z) {
    int64_t best = -1;
    for (uint32_t k = 0; k < dims.nz; ++k) {
        for (uint32_t j = 0; j < dims.ny; ++j) {
            for (uint32_t i = 0; i < dims.nx; ++i) {
                if (!feature[dims.index(i, j, k)]) continue;
                const int64_t d = (i - x) * (i - x) + (j - y) * (j - y) + (k - z) * (k - z);
                if (best < 0 || d < best) best = d;
            }
        }
    }
    return best < 0 ? kNoFeatureDistance : float(best);
}

/** Compare every voxel with brute force, exactly. */
void expectMatchesBruteForce(const std::vector<uint8_t>& feature, const GridDims& dims,
                             const std::string& label) {
    const std::vector<float> dt = squaredDistanceTransform(feature, dims);
    ASSERT_EQ(dt.size(), dims.count()) << label;
    int mismatches = 0;
    for (uint32_t z = 0; z < dims.nz; ++z) {
        for (uint32_t y = 0; y < dims.ny; ++y) {
            for (uint32_t x = 0; x < dims.nx; ++x) {
                const float expected = bruteForceAt(feature, dims, x, y, z);
                const float got = dt[dims.index(x, y, z)];
                if (got != expected && ++mismatches <= 5) {
                    ADD_FAILURE() << label << " at (" << x << "," << y << "," << z << "): got "
                                  << got << ", brute force " << expected;
                }
            }
        }
    }
    EXPECT_EQ(mismatches, 0) << label;
}

}  // namespace

TEST(CpuDistanceTransform, MatchesBruteForceOnRandomGrids) {
    const GridDims sizes[] = {{20, 20, 20}, {17, 11, 5}, {1, 17, 9}, {13, 1, 1},
                              {1, 1, 19},   {9, 1, 14},  {2, 3, 2},  {1, 1, 1}};
    const double densities[] = {0.001, 0.01, 0.05, 0.2, 0.5};
    uint32_t seed = 1;
    for (const GridDims& dims : sizes) {
        for (double density : densities) {
            const std::string label = std::to_string(dims.nx) + "x" + std::to_string(dims.ny) +
                                      "x" + std::to_string(dims.nz) +
                                      " density=" + std::to_string(density);
            expectMatchesBruteForce(randomFeatures(dims, density, seed++), dims, label);
        }
    }
}

TEST(CpuDistanceTransform, MatchesBruteForceOnSparseFeatureClusters) {
    // Few features far apart: long parabola envelopes with far-away intersections.
    const GridDims dims{23, 19, 21};
    for (uint32_t seed = 100; seed < 106; ++seed) {
        std::vector<uint8_t> feature(dims.count(), 0);
        std::mt19937 rng(seed);
        for (int i = 0; i < 3; ++i)
            feature[rng() % feature.size()] = 1;
        expectMatchesBruteForce(feature, dims, "clusters seed=" + std::to_string(seed));
    }
}

TEST(CpuDistanceTransform, SingleFeatureGivesSquaredRadius) {
    const GridDims dims{9, 12, 7};
    const uint32_t fx = 3, fy = 10, fz = 0;
    std::vector<uint8_t> feature(dims.count(), 0);
    feature[dims.index(fx, fy, fz)] = 1;
    const std::vector<float> dt = squaredDistanceTransform(feature, dims);
    const std::vector<float> d = distanceTransform(feature, dims);
    for (uint32_t z = 0; z < dims.nz; ++z) {
        for (uint32_t y = 0; y < dims.ny; ++y) {
            for (uint32_t x = 0; x < dims.nx; ++x) {
                const int dx = int(x) - int(fx), dy = int(y) - int(fy), dz = int(z) - int(fz);
                const float r2 = float(dx * dx + dy * dy + dz * dz);
                ASSERT_EQ(dt[dims.index(x, y, z)], r2) << x << "," << y << "," << z;
                ASSERT_FLOAT_EQ(d[dims.index(x, y, z)], std::sqrt(r2));
            }
        }
    }
}

TEST(CpuDistanceTransform, AllFeatureIsZeroAndNoFeatureIsInfinite) {
    const GridDims dims{6, 5, 4};
    for (float value : squaredDistanceTransform(std::vector<uint8_t>(dims.count(), 1), dims)) {
        ASSERT_EQ(value, 0.0f);
    }
    for (float value : squaredDistanceTransform(std::vector<uint8_t>(dims.count(), 0), dims)) {
        ASSERT_TRUE(std::isinf(value) && value > 0.0f);
        ASSERT_EQ(value, kNoFeatureDistance);
    }
}

TEST(CpuDistanceTransform, BadInputThrowsNamingTheProblem) {
    auto expectThrows = [](const std::vector<uint8_t>& feature, const GridDims& dims,
                           const std::string& needle) {
        try {
            squaredDistanceTransform(feature, dims);
            ADD_FAILURE() << "no throw for " << needle;
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
        }
    };
    expectThrows(std::vector<uint8_t>(7, 0), {2, 2, 2}, "needs 8 feature values, got 7");
    expectThrows(std::vector<uint8_t>(9, 0), {2, 2, 2}, "got 9");
    expectThrows({}, {0, 4, 4}, "zero dimension");
    expectThrows({}, {4, 4, 0}, "zero dimension");
    expectThrows(std::vector<uint8_t>(5000, 0), {5000, 1, 1}, "too large");
}

TEST(CpuDistanceTransform, Runs128CubedAndSpotChecks) {
    const GridDims dims{128, 128, 128};
    const std::vector<uint8_t> feature = randomFeatures(dims, 0.0005, 42);
    const auto start = std::chrono::steady_clock::now();
    const std::vector<float> dt = squaredDistanceTransform(feature, dims);
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    std::printf("[ INFO     ] 128^3 squared distance transform: %.1f ms\n", ms);
    std::mt19937 rng(7);
    for (int i = 0; i < 20; ++i) {
        const uint32_t x = rng() % dims.nx, y = rng() % dims.ny, z = rng() % dims.nz;
        ASSERT_EQ(dt[dims.index(x, y, z)], bruteForceAt(feature, dims, x, y, z))
            << x << "," << y << "," << z;
    }
}

// ---------------------------------------------------------------------------------------------
// Chessboard distance and opening
// ---------------------------------------------------------------------------------------------

namespace {

std::string label(const GridDims& dims, const std::string& what) {
    return std::to_string(dims.nx) + "x" + std::to_string(dims.ny) + "x" + std::to_string(dims.nz) +
           " " + what;
}

int64_t chessboardNorm(int64_t dx, int64_t dy, int64_t dz) {
    return std::max({std::abs(dx), std::abs(dy), std::abs(dz)});
}

/** O(voxels * features) chessboard distance map, kNoFeatureChessboard if no feature. */
std::vector<uint32_t> bruteChessboard(const std::vector<uint8_t>& feature, const GridDims& dims) {
    std::vector<std::array<int64_t, 3>> features;
    for (uint32_t z = 0; z < dims.nz; ++z)
        for (uint32_t y = 0; y < dims.ny; ++y)
            for (uint32_t x = 0; x < dims.nx; ++x)
                if (feature[dims.index(x, y, z)]) features.push_back({x, y, z});
    std::vector<uint32_t> out(dims.count(), kNoFeatureChessboard);
    for (uint32_t z = 0; z < dims.nz; ++z)
        for (uint32_t y = 0; y < dims.ny; ++y)
            for (uint32_t x = 0; x < dims.nx; ++x) {
                int64_t best = -1;
                for (const auto& f : features) {
                    const int64_t d = chessboardNorm(f[0] - x, f[1] - y, f[2] - z);
                    if (best < 0 || d < best) best = d;
                }
                if (best >= 0) out[dims.index(x, y, z)] = uint32_t(best);
            }
    return out;
}

/** O(voxels^2) opening: max d(c) over centres c whose cube of half-width d(c) - 1 holds x. */
std::vector<uint32_t> bruteOpening(const std::vector<uint32_t>& d, const GridDims& dims) {
    std::vector<uint32_t> out(dims.count(), 0);
    for (uint32_t cz = 0; cz < dims.nz; ++cz)
        for (uint32_t cy = 0; cy < dims.ny; ++cy)
            for (uint32_t cx = 0; cx < dims.nx; ++cx) {
                const int64_t r = int64_t(d[dims.index(cx, cy, cz)]) - 1;
                if (r < 0) continue;
                for (int64_t z = std::max<int64_t>(0, cz - r);
                     z <= std::min<int64_t>(dims.nz - 1, cz + r); ++z)
                    for (int64_t y = std::max<int64_t>(0, cy - r);
                         y <= std::min<int64_t>(dims.ny - 1, cy + r); ++y)
                        for (int64_t x = std::max<int64_t>(0, cx - r);
                             x <= std::min<int64_t>(dims.nx - 1, cx + r); ++x) {
                            uint32_t& o = out[dims.index(x, y, z)];
                            o = std::max(o, uint32_t(r + 1));
                        }
            }
    for (size_t i = 0; i < d.size(); ++i)
        if (d[i] == 0) out[i] = 0;
    return out;
}

/** Exact comparison, reporting the first few mismatches. */
void expectSameMap(const std::vector<uint32_t>& got, const std::vector<uint32_t>& expected,
                   const GridDims& dims, const std::string& what) {
    ASSERT_EQ(got.size(), expected.size()) << what;
    int mismatches = 0;
    for (uint32_t z = 0; z < dims.nz; ++z)
        for (uint32_t y = 0; y < dims.ny; ++y)
            for (uint32_t x = 0; x < dims.nx; ++x) {
                const size_t i = dims.index(x, y, z);
                if (got[i] != expected[i] && ++mismatches <= 5) {
                    ADD_FAILURE() << what << " at (" << x << "," << y << "," << z << "): got "
                                  << got[i] << ", brute force " << expected[i];
                }
            }
    EXPECT_EQ(mismatches, 0) << what;
}

const GridDims kChessboardSizes[] = {{20, 20, 20}, {17, 9, 23}, {1, 17, 9}, {13, 1, 1},
                                     {1, 1, 19},   {9, 1, 14},  {2, 3, 2},  {1, 1, 1}};

}  // namespace

TEST(CpuChessboardDistance, MatchesBruteForceOnRandomGrids) {
    uint32_t seed = 1000;
    size_t maxDistance = 0;
    for (const GridDims& dims : kChessboardSizes) {
        for (double density : {0.0005, 0.003, 0.01, 0.05, 0.2, 0.6}) {
            const std::vector<uint8_t> feature = randomFeatures(dims, density, seed++);
            const std::vector<uint32_t> got = chessboardDistanceTransform(feature, dims);
            const std::vector<uint32_t> expected = bruteChessboard(feature, dims);
            expectSameMap(got, expected, dims, label(dims, "density " + std::to_string(density)));
            for (uint32_t v : expected)
                if (v != kNoFeatureChessboard) maxDistance = std::max<size_t>(maxDistance, v);
        }
    }
    EXPECT_GE(maxDistance, 8u);  // far distances were exercised, not just 0 and 1
}

TEST(CpuChessboardDistance, MatchesBruteForceOnSparseFeatures) {
    // One to four features in a larger grid: long cones, wide flat tops in the y and z passes.
    const GridDims dims{31, 26, 28};
    for (uint32_t seed = 200; seed < 208; ++seed) {
        std::vector<uint8_t> feature(dims.count(), 0);
        std::mt19937 rng(seed);
        for (uint32_t i = 0; i <= seed % 4; ++i)
            feature[rng() % feature.size()] = 1;
        expectSameMap(chessboardDistanceTransform(feature, dims), bruteChessboard(feature, dims),
                      dims, "sparse seed " + std::to_string(seed));
    }
}

TEST(CpuChessboardDistance, SingleFeatureAndNoFeature) {
    const GridDims dims{17, 9, 23};
    const uint32_t fx = 12, fy = 2, fz = 7;
    std::vector<uint8_t> feature(dims.count(), 0);
    feature[dims.index(fx, fy, fz)] = 1;
    const std::vector<uint32_t> d = chessboardDistanceTransform(feature, dims);
    for (uint32_t z = 0; z < dims.nz; ++z)
        for (uint32_t y = 0; y < dims.ny; ++y)
            for (uint32_t x = 0; x < dims.nx; ++x)
                ASSERT_EQ(
                    d[dims.index(x, y, z)],
                    uint32_t(chessboardNorm(int64_t(x) - fx, int64_t(y) - fy, int64_t(z) - fz)))
                    << x << "," << y << "," << z;
    EXPECT_EQ(d[dims.index(fx + 1, fy + 1, fz + 1)], 1u);  // corner neighbour
    EXPECT_EQ(d[dims.index(0, 8, 22)], 15u);               // max(12, 6, 15)

    const std::vector<uint32_t> none =
        chessboardDistanceTransform(std::vector<uint8_t>(dims.count(), 0), dims);
    ASSERT_EQ(none.size(), dims.count());
    for (uint32_t v : none)
        ASSERT_EQ(v, kNoFeatureChessboard);
    EXPECT_EQ(kNoFeatureChessboard, std::numeric_limits<uint32_t>::max());
    for (uint32_t v : chessboardDistanceTransform(std::vector<uint8_t>(dims.count(), 1), dims))
        ASSERT_EQ(v, 0u);
}

TEST(CpuChessboardOpening, MatchesBruteForceOnDistanceMaps) {
    uint32_t seed = 3000;
    size_t aboveDistance = 0;
    for (const GridDims& dims : kChessboardSizes) {
        for (double density : {0.003, 0.02, 0.1, 0.4}) {
            std::vector<uint8_t> feature = randomFeatures(dims, density, seed++);
            feature[dims.index(0, 0, 0)] = 1;  // at least one feature
            const std::vector<uint32_t> d = chessboardDistanceTransform(feature, dims);
            const std::vector<uint32_t> open = chessboardOpening(d, dims);
            expectSameMap(open, bruteOpening(d, dims), dims,
                          label(dims, "opening, density " + std::to_string(density)));
            for (size_t i = 0; i < d.size(); ++i) {
                ASSERT_GE(open[i], d[i]);  // a voxel lies in its own ball
                if (d[i] == 0) {
                    ASSERT_EQ(open[i], 0u);
                }
                aboveDistance += open[i] > d[i];
            }
        }
    }
    EXPECT_GT(aboveDistance, 1000u);  // many voxels lie in a larger ball than their own
}

TEST(CpuChessboardOpening, MatchesBruteForceOnArbitraryMaps) {
    // The separable passes are exact for any finite map, not only 1-Lipschitz distance maps.
    uint32_t seed = 4000;
    for (const GridDims& dims : {GridDims{14, 11, 9}, GridDims{17, 9, 23}, GridDims{1, 30, 2}}) {
        for (uint32_t maxValue : {3u, 8u, 25u}) {
            std::mt19937 rng(seed++);
            std::vector<uint32_t> map(dims.count());
            for (uint32_t& v : map)
                v = rng() % 100 < 60 ? 0 : rng() % (maxValue + 1);
            expectSameMap(chessboardOpening(map, dims), bruteOpening(map, dims), dims,
                          label(dims, "arbitrary map, max " + std::to_string(maxValue)));
        }
    }
}

TEST(CpuChessboardOpening, KnownBoxRoom) {
    // Empty 10x6x6 room inside a 1-voxel solid frame: distance to the frame, and every voxel of
    // the room lies in a cube of half-width 2 (centres x in [3, 8], y, z in {3, 4}): opening 3.
    const GridDims dims{12, 8, 8};
    std::vector<uint8_t> solid(dims.count(), 1);
    for (uint32_t z = 1; z < 7; ++z)
        for (uint32_t y = 1; y < 7; ++y)
            for (uint32_t x = 1; x < 11; ++x)
                solid[dims.index(x, y, z)] = 0;
    const std::vector<uint32_t> d = chessboardDistanceTransform(solid, dims);
    const std::vector<uint32_t> open = chessboardOpening(d, dims);
    EXPECT_EQ(d[dims.index(1, 1, 1)], 1u);
    EXPECT_EQ(d[dims.index(2, 3, 3)], 2u);
    EXPECT_EQ(d[dims.index(5, 3, 4)], 3u);
    for (uint32_t z = 0; z < dims.nz; ++z)
        for (uint32_t y = 0; y < dims.ny; ++y)
            for (uint32_t x = 0; x < dims.nx; ++x)
                ASSERT_EQ(open[dims.index(x, y, z)], solid[dims.index(x, y, z)] ? 0u : 3u)
                    << x << "," << y << "," << z;
}

TEST(CpuChessboard, BadInputThrowsNamingTheProblem) {
    auto expectThrows = [](auto call, const std::string& needle) {
        try {
            call();
            ADD_FAILURE() << "no throw for " << needle;
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
        }
    };
    expectThrows(
        [] {
            chessboardDistanceTransform(std::vector<uint8_t>(7), {2, 2, 2});
        },
        "needs 8 feature values, got 7");
    expectThrows([] { chessboardDistanceTransform({}, {0, 3, 3}); }, "zero dimension");
    expectThrows(
        [] {
            chessboardOpening(std::vector<uint32_t>(9), {2, 2, 2});
        },
        "needs 8 distance values, got 9");
    expectThrows([] { chessboardOpening({}, {3, 0, 3}); }, "zero dimension");
    std::vector<uint32_t> mixed(8, 1);
    mixed[3] = kNoFeatureChessboard;
    expectThrows([&] { chessboardOpening(mixed, {2, 2, 2}); }, "mixes 1 kNoFeatureChessboard");
    // A map without any feature is returned as it is.
    const std::vector<uint32_t> none(24, kNoFeatureChessboard);
    EXPECT_EQ(chessboardOpening(none, {2, 3, 4}), none);
}

TEST(CpuChessboard, Runs256CubedAndSpotChecks) {
    // 1 % random solid voxels plus a solid border, as a voxelized scene's empty space.
    const GridDims dims{256, 256, 256};
    std::vector<uint8_t> solid = randomFeatures(dims, 0.01, 77);
    for (uint32_t z = 0; z < dims.nz; ++z)
        for (uint32_t y = 0; y < dims.ny; ++y)
            for (uint32_t x = 0; x < dims.nx; ++x)
                if (x == 0 || y == 0 || z == 0 || x == 255 || y == 255 || z == 255)
                    solid[dims.index(x, y, z)] = 1;
    auto t0 = std::chrono::steady_clock::now();
    const std::vector<uint32_t> d = chessboardDistanceTransform(solid, dims);
    auto t1 = std::chrono::steady_clock::now();
    const std::vector<uint32_t> open = chessboardOpening(d, dims);
    auto t2 = std::chrono::steady_clock::now();
    std::printf("[ INFO     ] 256^3 chessboard distance %.1f ms, opening %.1f ms\n",
                std::chrono::duration<double, std::milli>(t1 - t0).count(),
                std::chrono::duration<double, std::milli>(t2 - t1).count());
    // Spot checks: d is the smallest r whose cube of half-width r holds a solid voxel; the
    // opening is at least d and no larger than the largest d around.
    const auto solidWithin = [&](int64_t x, int64_t y, int64_t z, int64_t r) {
        for (int64_t k = std::max<int64_t>(0, z - r); k <= std::min<int64_t>(255, z + r); ++k)
            for (int64_t j = std::max<int64_t>(0, y - r); j <= std::min<int64_t>(255, y + r); ++j)
                for (int64_t i = std::max<int64_t>(0, x - r); i <= std::min<int64_t>(255, x + r);
                     ++i)
                    if (solid[dims.index(i, j, k)]) return true;
        return false;
    };
    std::mt19937 rng(9);
    for (int n = 0; n < 300; ++n) {
        const uint32_t x = rng() % 256, y = rng() % 256, z = rng() % 256;
        const uint32_t v = d[dims.index(x, y, z)];
        ASSERT_TRUE(solidWithin(x, y, z, v)) << x << "," << y << "," << z;
        if (v > 0) {
            ASSERT_FALSE(solidWithin(x, y, z, int64_t(v) - 1)) << x << "," << y << "," << z;
        }
        ASSERT_GE(open[dims.index(x, y, z)], v);
    }
}
