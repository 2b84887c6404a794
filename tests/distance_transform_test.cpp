// core/voxel: exact Euclidean distance transform against brute force. No GPU needed.
#include <chrono>
#include <cmath>
#include <cstdio>
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
