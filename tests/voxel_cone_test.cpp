// Shared voxel cone-tracing module (core/voxel/cone_set, core/voxel/voxel_radiance,
// shaders/common/voxel_cone*.glsl) against hand-built volumes with known answers.
// Gpu* tests run with validation on and fail on any validation message.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <glm/glm.hpp>
#include <glm/gtc/constants.hpp>
#include <glm/gtc/packing.hpp>
#include "tests/gpu_test_fixture.h"

#include "core/util/error.h"
#include "core/vk/buffer.h"
#include "core/vk/context.h"
#include "core/vk/descriptors.h"
#include "core/vk/pipeline.h"
#include "core/voxel/cone_set.h"
#include "core/voxel/voxel_grid.h"
#include "core/voxel/voxel_radiance.h"

namespace gilab {
namespace {

constexpr float kPi = glm::pi<float>();

// ---------------------------------------------------------------------------------------------
// Cone sets (CPU)

void expectValidSet(const ConeSet& set, uint32_t count) {
    ASSERT_EQ(set.cones.size(), count);
    float sum = 0.0f;
    for (const VoxelCone& c : set.cones) {
        EXPECT_NEAR(glm::length(c.direction), 1.0f, 1e-5f);
        EXPECT_GT(c.direction.z, 0.0f);  // axis inside the hemisphere
        EXPECT_GT(c.weight, 0.0f);
        sum += c.weight;
    }
    EXPECT_NEAR(sum, kPi, 1e-5f);
    EXPECT_NEAR(set.cones[0].direction.z, 1.0f, 1e-6f);
}

TEST(CpuConeSet, WeightsSumToPiDirectionsUnitInHemisphere) {
    for (uint32_t count : {1u, 3u, 5u, 6u, 9u, 16u})
        for (float aperture : {10.0f, 60.0f, 90.0f, 150.0f})
            for (float tilt : {-1.0f, 0.0f, 30.0f, 60.0f, 89.0f}) {
                SCOPED_TRACE(std::to_string(count) + " cones, " + std::to_string(aperture) +
                             " deg aperture, tilt " + std::to_string(tilt));
                expectValidSet(makeDiffuseConeSet(count, aperture, tilt), count);
            }
}

TEST(CpuConeSet, SixSixtyDegreeConesTrueTiltAndCosineWeights) {
    const ConeSet set = makeDiffuseConeSet(6, 60.0f);
    expectValidSet(set, 6);
    EXPECT_NEAR(set.apertureRad, glm::radians(60.0f), 1e-6f);
    for (size_t i = 1; i < 6; ++i) {
        // Default tilt 60 deg (notes 003 §8), 72 deg azimuth steps from 45/5 = 9 deg.
        EXPECT_NEAR(std::acos(set.cones[i].direction.z), glm::radians(60.0f), 1e-5f);
        const float phi = std::atan2(set.cones[i].direction.y, set.cones[i].direction.x);
        const float expected = glm::radians(9.0f + 72.0f * float(i - 1));
        EXPECT_NEAR(std::cos(phi - expected), 1.0f, 1e-5f);
    }
    // Unclipped cones: weight ~ pi sin^2(h) cos(tilt), so the side cones get half the normal
    // cone's weight: pi / 3.5 and pi / 7.
    EXPECT_NEAR(set.cones[0].weight, kPi / 3.5f, 1e-4f);
    EXPECT_NEAR(set.cones[1].weight, kPi / 7.0f, 1e-4f);
}

TEST(CpuConeSet, RingConesNeverAimAlongTangentAxes) {
    // The tangent frame follows the world axes, so an axis-aligned ring aims its cones straight
    // at the walls of an axis-aligned room (issue 9: the 3-cone set's old orientation).
    for (uint32_t count = 2; count <= kMaxCones; ++count) {
        const ConeSet set = makeDiffuseConeSet(count, 60.0f);
        const float ring = float(count - 1);
        // Closest approach of a ring of m equal steps offset by 45/m deg to a multiple of 90.
        const float margin = std::min(2.0f, 22.0f / ring);
        for (size_t i = 1; i < set.cones.size(); ++i) {
            const glm::vec3 d = set.cones[i].direction;
            const float phi = glm::degrees(std::atan2(d.y, d.x));
            const float toAxis = std::abs(std::remainder(phi, 90.0f));
            EXPECT_GT(toAxis, margin) << count << " cones, cone " << i << " at " << phi << " deg";
        }
    }
    EXPECT_NEAR(glm::degrees(ringAzimuthOffset(2)), 22.5f, 1e-4f);  // 3 cones: 22.5 and 202.5
}

TEST(CpuConeSet, CosineWeightedSolidAngleMatchesClosedForm) {
    for (float h : {0.1f, 0.5f, 1.0f}) {
        EXPECT_NEAR(coneCosineWeightedSolidAngle(h, 0.0f), kPi * std::sin(h) * std::sin(h), 1e-4f);
        const float tilt = 0.4f;  // h + tilt < pi/2: no clipping
        EXPECT_NEAR(coneCosineWeightedSolidAngle(h, tilt),
                    kPi * std::sin(h) * std::sin(h) * std::cos(tilt), 1e-4f);
    }
    // The whole hemisphere: integral of cos = pi. A clipped cone gives less than the unclipped
    // formula (which would count negative cosines).
    EXPECT_NEAR(coneCosineWeightedSolidAngle(0.5f * kPi, 0.0f), kPi, 1e-3f);
    const float h = 0.8f, tilt = 1.2f;
    EXPECT_GT(coneCosineWeightedSolidAngle(h, tilt),
              kPi * std::sin(h) * std::sin(h) * std::cos(tilt));
}

TEST(CpuConeSet, SingleConeAndZeroTilt) {
    const ConeSet one = makeDiffuseConeSet(1, 90.0f);
    ASSERT_EQ(one.cones.size(), 1u);
    EXPECT_NEAR(one.cones[0].weight, kPi, 1e-6f);
    const ConeSet flat = makeDiffuseConeSet(4, 30.0f, 0.0f);
    for (const VoxelCone& c : flat.cones) {
        EXPECT_NEAR(c.direction.z, 1.0f, 1e-6f);
        EXPECT_NEAR(c.weight, kPi / 4.0f, 1e-5f);
    }
}

void expectThrowsNaming(const std::function<void()>& f, const std::string& key) {
    try {
        f();
        ADD_FAILURE() << "no exception, expected one naming " << key;
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
    }
}

TEST(CpuConeSet, BadArgumentsThrow) {
    expectThrowsNaming([] { makeDiffuseConeSet(0, 60.0f); }, "count");
    expectThrowsNaming([] { makeDiffuseConeSet(17, 60.0f); }, "count");
    expectThrowsNaming([] { makeDiffuseConeSet(6, 0.0f); }, "aperture");
    expectThrowsNaming([] { makeDiffuseConeSet(6, 180.0f); }, "aperture");
    expectThrowsNaming([] { makeDiffuseConeSet(6, -5.0f); }, "aperture");
    expectThrowsNaming([] { makeDiffuseConeSet(6, std::nanf("")); }, "aperture");
    expectThrowsNaming([] { makeDiffuseConeSet(6, 60.0f, 90.0f); }, "tilt");
    expectThrowsNaming([] { makeDiffuseConeSet(6, 60.0f, std::nanf("")); }, "tilt");
    ConeSet big;
    big.cones.resize(17, VoxelCone{glm::vec3(0, 0, 1), 1.0f});
    expectThrowsNaming([&] { toGpu(big); }, "cones");
}

TEST(CpuConeSet, ToGpuPacks) {
    const ConeSet set = makeDiffuseConeSet(5, 60.0f, 45.0f);
    const GpuConeSet gpu = toGpu(set);
    EXPECT_EQ(gpu.info.x, 5.0f);
    EXPECT_NEAR(gpu.info.y, std::tan(glm::radians(30.0f)), 1e-6f);
    for (size_t i = 0; i < 5; ++i) {
        EXPECT_EQ(glm::vec3(gpu.cones[i]), set.cones[i].direction);
        EXPECT_EQ(gpu.cones[i].w, set.cones[i].weight);
    }
    for (size_t i = 5; i < kMaxCones; ++i)
        EXPECT_EQ(gpu.cones[i], glm::vec4(0.0f));
}

TEST(CpuVoxelRadianceMemory, FormulaPerResolution) {
    // Base N^3 + 6 faces of (N/2)^3 with mips (~6/7 N^3) at 8 bytes per texel.
    VoxelRadianceOptions aniso;
    const size_t n = 64, filtered = 32 * 32 * 32 + 16 * 16 * 16 + 8 * 8 * 8 + 64 + 8 + 1;
    EXPECT_EQ(VoxelRadiance::memoryBytesFor(64, aniso), 8 * (n * n * n + 6 * filtered));
    VoxelRadianceOptions iso;
    iso.anisotropic = false;
    iso.fullPrecision = true;
    EXPECT_EQ(VoxelRadiance::memoryBytesFor(64, iso), 16 * (n * n * n + filtered));
}

// ---------------------------------------------------------------------------------------------
// GPU helpers

using Volume = std::vector<glm::vec4>;

size_t idx(uint32_t n, int x, int y, int z) {
    return size_t(x) + n * (size_t(y) + size_t(n) * size_t(z));
}

VoxelGrid testGrid(uint32_t n = 32) {
    return VoxelGrid::fromCube(glm::vec3(-1.0f), 2.0f, n);
}

/** Copies `data` (x + N (y + N z)) into base() and filters, in one submission. */
void uploadAndFilter(vk::Context& ctx, VoxelRadiance& rad, const Volume& data) {
    const uint32_t n = rad.grid().resolution();
    const bool f32 = rad.format() == VK_FORMAT_R32G32B32A32_SFLOAT;
    std::vector<uint8_t> bytes(data.size() * (f32 ? 16 : 8));
    for (size_t i = 0; i < data.size(); ++i) {
        if (f32) {
            std::memcpy(&bytes[16 * i], &data[i], 16);
        } else {
            const glm::uint64 h = glm::packHalf4x16(data[i]);
            std::memcpy(&bytes[8 * i], &h, 8);
        }
    }
    vk::Buffer staging(ctx, bytes.size(), VK_BUFFER_USAGE_TRANSFER_SRC_BIT, vk::MemoryUsage::Upload,
                       "test/staging");
    staging.upload(bytes.data(), bytes.size());
    ctx.submitAndWait([&](VkCommandBuffer cmd) {
        rad.clearBase(cmd);
        rad.base().transition(cmd, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL);
        VkBufferImageCopy copy{};
        copy.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
        copy.imageExtent = {n, n, n};
        vkCmdCopyBufferToImage(cmd, staging.handle(), rad.base().handle(),
                               VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &copy);
        rad.base().transition(cmd, VK_IMAGE_LAYOUT_GENERAL);
        rad.filter(cmd);
    });
}

void expectVec4Near(const glm::vec4& a, const glm::vec4& b, float tol, const std::string& what) {
    for (int k = 0; k < 4; ++k)
        EXPECT_NEAR(a[k], b[k], tol) << what << " channel " << k << ": got (" << a.x << ", " << a.y
                                     << ", " << a.z << ", " << a.w << ")";
}

bool allFinite(const Volume& v) {
    for (const glm::vec4& x : v)
        for (int k = 0; k < 4; ++k)
            if (!std::isfinite(x[k])) return false;
    return true;
}

VoxelRadianceOptions exactAniso() {
    VoxelRadianceOptions o;
    o.fullPrecision = true;
    return o;
}

VoxelRadianceOptions exactIso(VoxelMipFilter filter) {
    VoxelRadianceOptions o;
    o.anisotropic = false;
    o.isotropicFilter = filter;
    o.fullPrecision = true;
    return o;
}

const glm::vec4 kRed(1, 0, 0, 1), kGreen(0, 1, 0, 1);

// ---------------------------------------------------------------------------------------------
// Filters

class GpuVoxelRadiance : public test::ValidatedGpuTest {};

TEST_F(GpuVoxelRadiance, AnisotropicRedInFrontOfGreen) {
    // Even x red, odd x green everywhere: every 2x2x2 block has red at its low x, green at its
    // high x. Rays toward -X (face 0) enter the larger-x child first: green only.
    const uint32_t n = 32;
    VoxelRadiance rad(*m_ctx, testGrid(n), exactAniso(), "test/radiance");
    Volume v(size_t(n) * n * n);
    for (int z = 0; z < int(n); ++z)
        for (int y = 0; y < int(n); ++y)
            for (int x = 0; x < int(n); ++x)
                v[idx(n, x, y, z)] = (x % 2 == 0) ? kRed : kGreen;
    uploadAndFilter(*m_ctx, rad, v);
    EXPECT_EQ(rad.readLevel(0, 0)[idx(n, 2, 3, 4)], kRed);
    const glm::vec4 expected[6] = {kGreen,
                                   kRed,
                                   {0.5f, 0.5f, 0, 1},
                                   {0.5f, 0.5f, 0, 1},
                                   {0.5f, 0.5f, 0, 1},
                                   {0.5f, 0.5f, 0, 1}};
    for (int f = 0; f < 6; ++f) {
        const Volume l1 = rad.readLevel(1, f);
        ASSERT_EQ(l1.size(), size_t(16 * 16 * 16));
        for (const glm::vec4& x : l1)
            ASSERT_EQ(x, expected[f]) << "face " << f;
        // Higher levels: the same pattern repeats (opaque fronts), so the values persist.
        const Volume l2 = rad.readLevel(2, f);
        expectVec4Near(l2[idx(8, 3, 4, 5)], expected[f], 1e-6f,
                       "level 2 face " + std::to_string(f));
    }
}

TEST_F(GpuVoxelRadiance, AnisotropicHalfFilledAndTranslucent) {
    const uint32_t n = 32;
    VoxelRadiance rad(*m_ctx, testGrid(n), exactAniso(), "test/radiance");
    Volume v(size_t(n) * n * n, glm::vec4(0.0f));
    // Block (0,0,0): only the x = 0 layer, opaque white -> opacity 1 along x, 0.5 along y and z.
    for (int z = 0; z < 2; ++z)
        for (int y = 0; y < 2; ++y)
            v[idx(n, 0, y, z)] = glm::vec4(1.0f);
    // Block (2,0,0): translucent red (a = 0.5, premultiplied) at x = 4 in front of opaque
    // green at x = 5. Toward -X: green then red: green. Toward +X: 0.5 red + 0.5 green.
    for (int z = 0; z < 2; ++z)
        for (int y = 0; y < 2; ++y) {
            v[idx(n, 4, y, z)] = glm::vec4(0.5f, 0.0f, 0.0f, 0.5f);
            v[idx(n, 5, y, z)] = kGreen;
        }
    uploadAndFilter(*m_ctx, rad, v);
    const float halfAlpha[6] = {1.0f, 1.0f, 0.5f, 0.5f, 0.5f, 0.5f};
    for (int f = 0; f < 6; ++f) {
        const Volume l1 = rad.readLevel(1, f);
        EXPECT_NEAR(l1[idx(16, 0, 0, 0)].a, halfAlpha[f], 1e-6f) << "face " << f;
        EXPECT_NEAR(l1[idx(16, 0, 0, 0)].r, halfAlpha[f], 1e-6f) << "face " << f;
        EXPECT_EQ(l1[idx(16, 1, 0, 0)], glm::vec4(0.0f)) << "face " << f;
    }
    expectVec4Near(rad.readLevel(1, 0)[idx(16, 2, 0, 0)], kGreen, 1e-6f, "-X");
    expectVec4Near(rad.readLevel(1, 1)[idx(16, 2, 0, 0)], glm::vec4(0.5f, 0.5f, 0.0f, 1.0f), 1e-6f,
                   "+X");
    // Along y: pairs are (red, red) and (green, green): 1/2 [(0.75 red, a 0.75) + green].
    expectVec4Near(rad.readLevel(1, 3)[idx(16, 2, 0, 0)], glm::vec4(0.375f, 0.5f, 0.0f, 0.875f),
                   1e-6f, "+Y");
}

TEST_F(GpuVoxelRadiance, AnisotropicMipChainOfHomogeneousMedium) {
    // A homogeneous medium of opacity a per voxel: each level's opacity must be
    // 1 - (1 - a)^(cell size / v0) in the interior, in every direction, down to 1^3.
    const uint32_t n = 32;
    VoxelRadiance rad(*m_ctx, testGrid(n), exactAniso(), "test/radiance");
    EXPECT_EQ(rad.levels(), 6u);
    const float a = 0.25f;
    uploadAndFilter(*m_ctx, rad, Volume(size_t(n) * n * n, glm::vec4(0.5f * a, a, 0.0f, a)));
    for (uint32_t level = 1; level < rad.levels(); ++level) {
        const uint32_t size = n >> level;
        const float expected = 1.0f - std::pow(1.0f - a, float(1u << level));
        for (int f = 0; f < 6; ++f) {
            const Volume l = rad.readLevel(level, f);
            ASSERT_EQ(l.size(), size_t(size) * size * size);
            ASSERT_TRUE(allFinite(l));
            for (const glm::vec4& x : l) {
                ASSERT_NEAR(x.a, expected, 1e-5f) << "level " << level << " face " << f;
                ASSERT_NEAR(x.g, expected, 1e-5f);  // colour stays proportional
                ASSERT_NEAR(x.r, 0.5f * expected, 1e-5f);
            }
        }
    }
    EXPECT_THROW(rad.readLevel(6, 0), Error);
    EXPECT_THROW(rad.readLevel(1, 6), Error);
}

TEST_F(GpuVoxelRadiance, BoxImpulseAndConstant) {
    const uint32_t n = 32;
    VoxelRadiance rad(*m_ctx, testGrid(n), exactIso(VoxelMipFilter::Box), "test/radiance");
    Volume v(size_t(n) * n * n, glm::vec4(0.0f));
    const glm::vec4 impulse(1.0f, 2.0f, 3.0f, 1.0f);
    v[idx(n, 11, 10, 10)] = impulse;
    uploadAndFilter(*m_ctx, rad, v);
    const Volume l1 = rad.readLevel(1, 0);
    for (int z = 0; z < 16; ++z)
        for (int y = 0; y < 16; ++y)
            for (int x = 0; x < 16; ++x) {
                const glm::vec4 expected =
                    (x == 5 && y == 5 && z == 5) ? impulse / 8.0f : glm::vec4(0.0f);
                ASSERT_EQ(l1[idx(16, x, y, z)], expected) << x << " " << y << " " << z;
            }
    // Isotropic: every face index reads the same volume.
    EXPECT_EQ(rad.readLevel(1, 4), l1);
    const glm::vec4 c(0.2f, 0.4f, 0.6f, 1.0f);
    uploadAndFilter(*m_ctx, rad, Volume(size_t(n) * n * n, c));
    for (uint32_t level = 1; level < rad.levels(); ++level)
        for (const glm::vec4& x : rad.readLevel(level, 0))
            expectVec4Near(x, c, 1e-6f, "box level " + std::to_string(level));
}

TEST_F(GpuVoxelRadiance, GaussianImpulseWeightsAndConstantInterior) {
    const uint32_t n = 32;
    VoxelRadiance rad(*m_ctx, testGrid(n), exactIso(VoxelMipFilter::Gaussian), "test/radiance");
    Volume v(size_t(n) * n * n, glm::vec4(0.0f));
    v[idx(n, 10, 10, 10)] = glm::vec4(1.0f);
    uploadAndFilter(*m_ctx, rad, v);
    // Fine cell 10 lies in the 4-tap support of coarse cells 4 (tap 3: 1/8) and 5 (tap 1: 3/8).
    auto w1 = [](int c) { return c == 4 ? 0.125f : c == 5 ? 0.375f : 0.0f; };
    const Volume l1 = rad.readLevel(1, 0);
    float total = 0.0f;
    for (int z = 0; z < 16; ++z)
        for (int y = 0; y < 16; ++y)
            for (int x = 0; x < 16; ++x) {
                const float w = w1(x) * w1(y) * w1(z);
                ASSERT_NEAR(l1[idx(16, x, y, z)].a, w, 1e-7f) << x << " " << y << " " << z;
                total += l1[idx(16, x, y, z)].a;
            }
    EXPECT_NEAR(total, 1.0f / 8.0f, 1e-6f);  // mass preserved (per coarse-cell volume)
    const glm::vec4 c(0.2f, 0.4f, 0.6f, 1.0f);
    uploadAndFilter(*m_ctx, rad, Volume(size_t(n) * n * n, c));
    for (uint32_t level = 1; level < rad.levels() - 1; ++level) {
        const uint32_t s = n >> level;
        const Volume l = rad.readLevel(level, 0);
        ASSERT_TRUE(allFinite(l));
        for (uint32_t z = 1; z + 1 < s; ++z)
            for (uint32_t y = 1; y + 1 < s; ++y)
                for (uint32_t x = 1; x + 1 < s; ++x)
                    expectVec4Near(l[idx(s, x, y, z)], c, 1e-5f, "interior");
    }
    // Level 1 boundary: the outside counts as empty, losing 1/8 per boundary axis.
    expectVec4Near(rad.readLevel(1, 0)[idx(16, 0, 5, 5)], c * 0.875f, 1e-6f, "boundary");
}

TEST_F(GpuVoxelRadiance, HalfPrecisionNoNaNAndResolutionChecks) {
    const uint32_t n = 32;
    VoxelRadiance rad(*m_ctx, testGrid(n), VoxelRadianceOptions{}, "test/radiance");
    EXPECT_EQ(rad.format(), VK_FORMAT_R16G16B16A16_SFLOAT);
    EXPECT_EQ(rad.memoryBytes(), VoxelRadiance::memoryBytesFor(n, VoxelRadianceOptions{}));
    // Pseudo-random sparse content, including zeros, big HDR values and a = 0 cells.
    Volume v(size_t(n) * n * n, glm::vec4(0.0f));
    uint32_t state = 12345u;
    auto rnd = [&] {
        state = state * 1664525u + 1013904223u;
        return float(state >> 8) / float(1u << 24);
    };
    for (glm::vec4& x : v) {
        if (rnd() < 0.3f) {
            const float a = rnd() < 0.5f ? 1.0f : rnd();
            x = glm::vec4(glm::vec3(rnd(), rnd(), rnd()) * 1000.0f * a, a);
        }
    }
    uploadAndFilter(*m_ctx, rad, v);
    for (uint32_t level = 0; level < rad.levels(); ++level)
        for (int f = 0; f < 6; ++f) {
            const Volume l = rad.readLevel(level, f);
            ASSERT_TRUE(allFinite(l)) << "level " << level << " face " << f;
            for (const glm::vec4& x : l)
                ASSERT_TRUE(x.a >= 0.0f && x.a <= 1.0f + 1e-3f);
            if (level == 0) break;
        }
    // Non power-of-two grids cannot halve down to 1^3.
    try {
        VoxelRadiance bad(*m_ctx, testGrid(48), VoxelRadianceOptions{}, "test/bad");
        ADD_FAILURE() << "no exception";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("resolution"), std::string::npos);
    }
}

// ---------------------------------------------------------------------------------------------
// Cone tracing through shaders/common/test_voxel_cone.comp

struct ConeTraceParams {
    glm::vec4 gridMinV0, gridMaxStep, distances, misc;
};
struct ConeQuery {
    glm::vec4 originTanHalf;
    glm::vec4 dirMode;
    ConeTraceParams params;
    glm::vec4 normal{0.0f};  // mode 3: surface normal, w origin offset
};
struct ConePush {
    GpuVoxelGrid grid;
    uint32_t anisotropic;
    uint32_t queryCount;
};

class ConeRunner {
public:
    // After VoxelRadiance's bindings 0..7 (shaders/common/test_voxel_cone.comp).
    static constexpr uint32_t kQueryBinding = 9, kResultBinding = 10;

    ConeRunner(vk::Context& ctx, VoxelRadiance& rad) : m_ctx(ctx), m_rad(rad) {
        std::vector<vk::DescriptorBinding> bindings;
        VoxelRadiance::addLayoutBindings(bindings, 0, VK_SHADER_STAGE_COMPUTE_BIT);
        bindings.push_back({kQueryBinding, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1,
                            VK_SHADER_STAGE_COMPUTE_BIT, false});
        bindings.push_back({kResultBinding, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1,
                            VK_SHADER_STAGE_COMPUTE_BIT, false});
        m_layout = vk::DescriptorSetLayout(ctx, bindings, "test/cone");
        m_pipelineLayout = vk::PipelineLayout(ctx, {m_layout.handle()}, sizeof(ConePush),
                                              VK_SHADER_STAGE_COMPUTE_BIT);
        m_pipeline = vk::ComputePipeline(ctx, "common/test_voxel_cone.comp", m_pipelineLayout);
    }

    ConeTraceParams params(float step = 0.5f, float maxDist = 100.0f, float lambda = 0.0f) const {
        const VoxelGrid& g = m_rad.grid();
        return {glm::vec4(g.origin(), g.voxelSize()),
                glm::vec4(g.origin() + glm::vec3(g.side()), step),
                glm::vec4(maxDist, 0.0f, 1.0f, lambda), glm::vec4(0.0f)};
    }

    std::vector<glm::vec4> run(const std::vector<ConeQuery>& queries) {
        vk::Buffer in(m_ctx, queries.size() * sizeof(ConeQuery), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                      vk::MemoryUsage::Upload, "test/queries");
        in.uploadVector(queries);
        vk::Buffer out(m_ctx, queries.size() * 16, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                       vk::MemoryUsage::Readback, "test/results");
        vk::DescriptorSet set(m_ctx, m_layout, 0, "test/cone");
        m_rad.writeDescriptors(set, 0);
        set.writeBuffer(kQueryBinding, in);
        set.writeBuffer(kResultBinding, out);
        ConePush push{m_rad.grid().gpu(), m_rad.options().anisotropic ? 1u : 0u,
                      uint32_t(queries.size())};
        m_ctx.submitAndWait([&](VkCommandBuffer cmd) {
            m_pipeline.bind(cmd);
            VkDescriptorSet s = set.handle();
            vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, m_pipelineLayout.handle(),
                                    0, 1, &s, 0, nullptr);
            m_pipelineLayout.push(cmd, push);
            vk::dispatch1D(cmd, uint32_t(queries.size()), 64);
        });
        return out.downloadVector<glm::vec4>(queries.size());
    }

    ConeQuery trace(glm::vec3 origin, glm::vec3 dir, float tanHalf, const ConeTraceParams& p,
                    int mode = 0) const {
        return {glm::vec4(origin, tanHalf), glm::vec4(dir, float(mode)), p};
    }
    ConeQuery sample(glm::vec3 pos, float lod, glm::vec3 dir) const {
        return {glm::vec4(pos, lod), glm::vec4(dir, 2.0f), params()};
    }
    ConeQuery surfaceCone(glm::vec3 point, glm::vec3 normal, float offset, glm::vec3 dir,
                          float tanHalf, const ConeTraceParams& p) const {
        return {glm::vec4(point, tanHalf), glm::vec4(dir, 3.0f), p, glm::vec4(normal, offset)};
    }
    ConeQuery level(float t, float tanHalf, const ConeTraceParams& p) const {
        return {glm::vec4(t, 0.0f, 0.0f, tanHalf), glm::vec4(1.0f, 0.0f, 0.0f, 4.0f), p};
    }

private:
    vk::Context& m_ctx;
    VoxelRadiance& m_rad;
    vk::DescriptorSetLayout m_layout;
    vk::PipelineLayout m_pipelineLayout;
    vk::ComputePipeline m_pipeline;
};

class GpuVoxelCone : public test::ValidatedGpuTest {};

TEST_F(GpuVoxelCone, EmptyGridGivesNothing) {
    const uint32_t n = 32;
    VoxelRadiance rad(*m_ctx, testGrid(n), VoxelRadianceOptions{}, "test/radiance");
    uploadAndFilter(*m_ctx, rad, Volume(size_t(n) * n * n, glm::vec4(0.0f)));
    ConeRunner runner(*m_ctx, rad);
    const ConeTraceParams p = runner.params();
    const std::vector<glm::vec4> r = runner.run({
        runner.trace(glm::vec3(0.0f), glm::vec3(1, 0, 0), 0.577f, p),
        runner.trace(glm::vec3(0.1f), glm::normalize(glm::vec3(-1, 2, 0.5f)), 0.05f, p),
        runner.trace(glm::vec3(0.0f), glm::vec3(0.0f), 0.577f, p),        // zero direction
        runner.trace(glm::vec3(0.0f), glm::vec3(0, 0, 1), 0.0f, p),       // zero aperture
        runner.trace(glm::vec3(5.0f), glm::vec3(0, 0, 1), 0.577f, p),     // outside the grid
        runner.trace(glm::vec3(0.0f), glm::vec3(0, 1, 0), 0.577f, p, 1),  // occlusion
        runner.trace(glm::vec3(0.0f), glm::vec3(0.0f), 0.577f, p, 1),
        runner.sample(glm::vec3(0.0f), 2.5f, glm::vec3(0.0f)),
    });
    for (size_t i = 0; i < r.size(); ++i) {
        const glm::vec4 expected = (i == 5 || i == 6) ? glm::vec4(0, 0, 0, 1) : glm::vec4(0.0f);
        EXPECT_EQ(r[i], expected) << "query " << i;
    }
}

Volume redGreenColumns(uint32_t n) {
    Volume v(size_t(n) * n * n);
    for (int z = 0; z < int(n); ++z)
        for (int y = 0; y < int(n); ++y)
            for (int x = 0; x < int(n); ++x)
                v[idx(n, x, y, z)] = (x % 2 == 0) ? kRed : kGreen;
    return v;
}

TEST_F(GpuVoxelCone, DenseSamplerLevelMappingAndDirections) {
    const uint32_t n = 32;
    VoxelRadiance rad(*m_ctx, testGrid(n), exactAniso(), "test/radiance");
    uploadAndFilter(*m_ctx, rad, redGreenColumns(n));
    ConeRunner runner(*m_ctx, rad);
    const VoxelGrid& g = rad.grid();
    const glm::vec3 redCentre = g.voxelCenter({10, 12, 14});  // even x: red
    const glm::vec3 mid(0.0f);
    const glm::vec3 yellow(0.5f, 0.5f, 0.0f);
    const std::vector<glm::vec4> r = runner.run({
        runner.sample(redCentre, 0.0f, glm::vec3(-1, 0, 0)),                     // base
        runner.sample(mid, 1.0f, glm::vec3(-1, 0, 0)),                           // -X: green
        runner.sample(mid, 1.0f, glm::vec3(1, 0, 0)),                            // +X: red
        runner.sample(mid, 1.0f, glm::vec3(0, 1, 0)),                            // +Y: mixed
        runner.sample(mid, 2.7f, glm::normalize(glm::vec3(-1, 1, 0))),           // dir^2
        runner.sample(redCentre, 0.5f, glm::vec3(-1, 0, 0)),                     // base/dir mix
        runner.sample(g.origin() - glm::vec3(0.01f), 0.0f, glm::vec3(1, 0, 0)),  // outside
    });
    expectVec4Near(r[0], kRed, 1e-6f, "base");
    expectVec4Near(r[1], kGreen, 1e-6f, "-X");
    expectVec4Near(r[2], kRed, 1e-6f, "+X");
    expectVec4Near(r[3], glm::vec4(yellow, 1.0f), 1e-6f, "+Y");
    expectVec4Near(r[4], 0.5f * kGreen + 0.5f * glm::vec4(yellow, 1.0f), 1e-5f, "-X+Y");
    expectVec4Near(r[5], 0.5f * kRed + 0.5f * kGreen, 1e-5f, "lod 0.5");
    EXPECT_EQ(r[6], glm::vec4(0.0f));
}

TEST_F(GpuVoxelCone, OpaqueEmittingWallReturnsItsRadiance) {
    const uint32_t n = 32;
    for (bool aniso : {true, false}) {
        SCOPED_TRACE(aniso ? "anisotropic" : "isotropic Gaussian");
        VoxelRadianceOptions o;
        o.anisotropic = aniso;
        VoxelRadiance rad(*m_ctx, testGrid(n), o, "test/radiance");
        const glm::vec4 wall(2.0f, 1.0f, 0.5f, 1.0f);  // radiance (premultiplied by a = 1)
        Volume v(size_t(n) * n * n, glm::vec4(0.0f));
        for (int z = 0; z < int(n); ++z)
            for (int y = 0; y < int(n); ++y)
                for (int x = 20; x < int(n); ++x)
                    v[idx(n, x, y, z)] = wall;
        uploadAndFilter(*m_ctx, rad, v);
        ConeRunner runner(*m_ctx, rad);
        const VoxelGrid& g = rad.grid();
        const glm::vec3 origin = g.gridToWorld(glm::vec3(6.0f, 16.0f, 16.0f));
        const std::vector<glm::vec4> r = runner.run({
            runner.trace(origin, glm::vec3(1, 0, 0), 0.05f, runner.params(0.5f)),
            runner.trace(origin, glm::vec3(1, 0, 0), 0.3f, runner.params(0.5f)),
            runner.trace(origin, glm::vec3(-1, 0, 0), 0.3f, runner.params(0.5f)),  // away
            runner.trace(origin, glm::vec3(1, 0, 0), 0.05f, runner.params(0.5f), 1),
        });
        // Narrow cone: the wall is 14 voxels ahead, opaque: full radiance, full opacity.
        expectVec4Near(r[0], wall, 0.02f, "narrow");
        // Wider cone: every sample has colour / opacity = the wall's radiance. Isotropic mips
        // halve the opacity of half-covered cells (the leak anisotropy fixes, Crassin §9).
        EXPECT_GT(r[1].a, aniso ? 0.9f : 0.5f);
        expectVec4Near(r[1], wall * r[1].a, 1e-3f, "wide");
        EXPECT_EQ(r[2], glm::vec4(0.0f));
        EXPECT_NEAR(r[3].a, 0.0f, 0.02f);  // fully occluded
    }
}

TEST_F(GpuVoxelCone, LevelIsTheConeRadiusLevel) {
    // Crassin §5: the level whose voxel size is the cone radius t tan(theta/2), plus the bias.
    const uint32_t n = 32;
    VoxelRadiance rad(*m_ctx, testGrid(n), exactAniso(), "test/radiance");
    ConeRunner runner(*m_ctx, rad);
    const float v0 = rad.grid().voxelSize();
    ConeTraceParams biased = runner.params();
    biased.misc.x = -1.0f;
    std::vector<ConeQuery> q;
    const float ts[4] = {4.0f, 8.0f, 16.0f, 24.0f};  // in v0
    for (float t : ts)
        q.push_back(runner.level(t * v0, 0.5f, runner.params()));
    for (float t : ts)
        q.push_back(runner.level(t * v0, 0.5f, biased));
    q.push_back(runner.level(0.5f * v0, 0.5f, runner.params()));  // below v0: level 0
    const std::vector<glm::vec4> r = runner.run(q);
    for (int i = 0; i < 4; ++i) {
        const float radiusLevel = std::log2(ts[i] * 0.5f);  // radius / v0 = t tan = t / 2
        EXPECT_NEAR(r[size_t(i)].x, radiusLevel, 1e-4f) << "t = " << ts[i] << " v0";
        EXPECT_NEAR(r[size_t(i) + 4].x, std::max(radiusLevel - 1.0f, 0.0f), 1e-4f);
    }
    EXPECT_EQ(r[8].x, 0.0f);
}

TEST_F(GpuVoxelCone, FacingHidesTheBackOfAWall) {
    // A one-voxel wall at x = 16 facing -x (toward x = 6). Seen from the front it shines, from
    // behind it is black but still opaque (Crassin §7: shade toward the cone through the
    // averaged normal); without normals it shines both ways.
    const uint32_t n = 32;
    const glm::vec4 wall(2.0f, 1.0f, 0.5f, 1.0f);
    Volume v(size_t(n) * n * n, glm::vec4(0.0f)), normals(size_t(n) * n * n, glm::vec4(0.0f));
    for (int z = 0; z < int(n); ++z)
        for (int y = 0; y < int(n); ++y) {
            v[idx(n, 16, y, z)] = wall;
            normals[idx(n, 16, y, z)] = glm::vec4(-1.0f, 0.0f, 0.0f, 1.0f);
        }
    vk::ImageDesc nd;
    nd.kind = vk::ImageKind::Image3D;
    nd.format = VK_FORMAT_R32G32B32A32_SFLOAT;
    nd.width = nd.height = nd.depth = n;
    nd.usage = VK_IMAGE_USAGE_SAMPLED_BIT;
    nd.name = "test/normals";
    vk::Image normalImage(*m_ctx, nd);
    normalImage.upload(*m_ctx, normals.data(), normals.size() * sizeof(glm::vec4));
    for (bool withNormals : {true, false}) {
        SCOPED_TRACE(withNormals ? "facing" : "isotropic");
        VoxelRadiance rad(*m_ctx, testGrid(n), VoxelRadianceOptions{}, "test/radiance");
        if (withNormals) rad.setSurfaceNormals(normalImage);
        uploadAndFilter(*m_ctx, rad, v);
        ConeRunner runner(*m_ctx, rad);
        const VoxelGrid& g = rad.grid();
        const glm::vec3 front = g.gridToWorld(glm::vec3(6.0f, 16.0f, 16.0f));
        const glm::vec3 back = g.gridToWorld(glm::vec3(27.0f, 16.0f, 16.0f));
        const std::vector<glm::vec4> r = runner.run({
            runner.trace(front, {1, 0, 0}, 0.05f, runner.params()),  // base level
            runner.trace(back, {-1, 0, 0}, 0.05f, runner.params()),
            runner.trace(front, {1, 0, 0}, 0.3f, runner.params()),  // directional levels
            runner.trace(back, {-1, 0, 0}, 0.3f, runner.params()),
        });
        for (int i : {0, 2}) {
            EXPECT_GT(r[size_t(i)].a, 0.5f) << i;
            EXPECT_NEAR(r[size_t(i)].r / r[size_t(i)].a, wall.r, 0.05f * wall.r) << i;
        }
        for (int i : {1, 3}) {
            EXPECT_NEAR(r[size_t(i)].a, r[size_t(i) - 1].a, 0.05f) << i;  // opacity both ways
            if (withNormals)
                EXPECT_LT(r[size_t(i)].r, 0.02f * wall.r) << i;
            else
                EXPECT_NEAR(r[size_t(i)].r, r[size_t(i) - 1].r, 0.05f * wall.r) << i;
        }
    }
}

TEST_F(GpuVoxelCone, LiftKeepsASurfaceOutOfItsOwnCones) {
    // An emitting floor (y < 6, isotropic: no normals) and a 60 deg cone leaving its top surface
    // tilted 60 deg: the lift keeps every sample 1.5 cells of its level above the plane, so the
    // floor's own cells are never gathered; without the lift the coarse cells return its light.
    const uint32_t n = 32;
    const glm::vec4 floorColor(1.0f, 1.0f, 1.0f, 1.0f);
    Volume v(size_t(n) * n * n, glm::vec4(0.0f));
    for (int z = 0; z < int(n); ++z)
        for (int y = 0; y < 6; ++y)  // not on a coarse cell boundary
            for (int x = 0; x < int(n); ++x)
                v[idx(n, x, y, z)] = floorColor;
    VoxelRadiance rad(*m_ctx, testGrid(n), VoxelRadianceOptions{}, "test/radiance");
    uploadAndFilter(*m_ctx, rad, v);
    ConeRunner runner(*m_ctx, rad);
    const VoxelGrid& g = rad.grid();
    const float v0 = g.voxelSize();
    const glm::vec3 point = g.gridToWorld(glm::vec3(16.0f, 6.0f, 16.0f));
    const glm::vec3 dir = glm::normalize(glm::vec3(std::sin(1.047f), std::cos(1.047f), 0.0f));
    ConeTraceParams lifted = runner.params(), flat = runner.params();
    lifted.misc.y = 1.5f;
    lifted.distances.y = flat.distances.y = 1.5f * v0;  // t0
    const std::vector<glm::vec4> r = runner.run({
        runner.surfaceCone(point, {0, 1, 0}, 1.5f * v0, dir, 0.577f, lifted),
        runner.surfaceCone(point, {0, 1, 0}, 1.5f * v0, dir, 0.577f, flat),
    });
    std::printf("floor light gathered: lifted %.4f, not lifted %.4f\n", r[0].r, r[1].r);
    EXPECT_LT(r[0].r, 1e-3f);
    EXPECT_GT(r[1].r, 0.01f);
}

// A measured limit of marching trilinearly filtered voxels (issue 43 item 1, techniques/vct/
// README.md "Energy against the grid resolution"): a ray of aperture 0 through an opaque shell one
// voxel thick samples the shell's opacity as a tent two voxels wide, and with the step
// correction the tent's optical depth is finite: at normal incidence 16-19 % of what lies behind
// passes (the shell gives 0.81-0.84 of its radiance) unless a sample lands on a voxel centre;
// at 45 deg 4-8 %; a shell two voxels thick is opaque.
TEST_F(GpuVoxelCone, AOneVoxelShellPassesAFifthOfALevelZeroRay) {
    const uint32_t n = 32;
    for (int thickness : {1, 2}) {
        VoxelRadiance rad(*m_ctx, testGrid(n), VoxelRadianceOptions{}, "test/radiance");
        const glm::vec4 wall(1.0f, 1.0f, 1.0f, 1.0f);
        Volume v(size_t(n) * n * n, glm::vec4(0.0f));
        for (int z = 0; z < int(n); ++z)
            for (int y = 0; y < int(n); ++y)
                for (int x = 20; x < 20 + thickness; ++x)
                    v[idx(n, x, y, z)] = wall;
        uploadAndFilter(*m_ctx, rad, v);
        ConeRunner runner(*m_ctx, rad);
        const VoxelGrid& g = rad.grid();
        std::vector<ConeQuery> q;
        for (float cosA : {1.0f, 0.7f})
            for (float phase : {0.13f, 0.25f, 0.37f})
                q.push_back(runner.trace(g.gridToWorld(glm::vec3(6.0f + phase, 12.0f, 16.0f)),
                                         glm::vec3(cosA, std::sqrt(1.0f - cosA * cosA), 0.0f), 0.0f,
                                         runner.params(0.5f)));
        const std::vector<glm::vec4> r = runner.run(q);
        for (size_t i = 0; i < r.size(); ++i) {
            SCOPED_TRACE("thickness " + std::to_string(thickness) + ", query " + std::to_string(i));
            EXPECT_NEAR(r[i].r, r[i].a, 1e-4f);  // radiance / opacity = the wall's
            if (thickness == 2) {
                EXPECT_GT(r[i].a, 0.999f);
            } else if (i < 3) {  // normal incidence
                EXPECT_GT(r[i].a, 0.79f);
                EXPECT_LT(r[i].a, 0.86f);
            } else {  // 45 deg
                EXPECT_GT(r[i].a, 0.90f);
                EXPECT_LT(r[i].a, 0.99f);
            }
        }
    }
}

TEST_F(GpuVoxelCone, OpacityCorrectionMakesStepFactorIrrelevant) {
    // Homogeneous medium of a = 0.1 per voxel, the cone fully inside it.
    const uint32_t n = 32;
    VoxelRadiance rad(*m_ctx, testGrid(n), exactAniso(), "test/radiance");
    const float a = 0.1f;
    uploadAndFilter(*m_ctx, rad, Volume(size_t(n) * n * n, glm::vec4(3.0f * a, 0, 0, a)));
    ConeRunner runner(*m_ctx, rad);
    const VoxelGrid& g = rad.grid();
    const float v0 = g.voxelSize();
    const glm::vec3 origin = g.gridToWorld(glm::vec3(8.0f, 16.0f, 16.0f));
    const float dist = 8.0f * v0;
    std::vector<ConeQuery> q;
    const float steps[3] = {0.25f, 0.5f, 1.0f};
    for (float k : steps)
        q.push_back(runner.trace(origin, {1, 0, 0}, 0.0f, runner.params(k, dist)));
    for (float k : steps)
        q.push_back(runner.trace(origin, {1, 0, 0}, 0.15f, runner.params(k, 12.0f * v0)));
    const std::vector<glm::vec4> r = runner.run(q);
    // Narrow cone at level 0: n samples of k v0 -> A = 1 - (1 - a)^(D / v0 + k).
    for (int i = 0; i < 3; ++i) {
        const float expected = 1.0f - std::pow(1.0f - a, 8.0f + steps[i]);
        EXPECT_NEAR(r[i].a, expected, 1e-3f) << "k = " << steps[i];
        EXPECT_NEAR(r[i].r, 3.0f * r[i].a, 1e-3f);
    }
    EXPECT_NEAR(r[0].a, r[2].a, 0.05f);
    // Growing cone (mixed levels): within a few percent across step factors (linear blending
    // between levels is not exactly exponential in the optical depth; coarse k = 1 samples).
    for (int i = 3; i < 6; ++i) {
        EXPECT_NEAR(r[i].a, r[3].a, i == 5 ? 0.06f : 0.03f) << "k = " << steps[i - 3];
        EXPECT_GT(r[i].a, 0.5f);
    }
    // Without the correction the results would differ by far more: a sanity check of the test.
    EXPECT_GT(std::abs((1.0f - std::pow(1.0f - a, 9.0f)) - (1.0f - std::pow(1.0f - a, 17.0f))),
              0.1f);
}

TEST_F(GpuVoxelCone, OcclusionFalloff) {
    const uint32_t n = 32;
    VoxelRadiance rad(*m_ctx, testGrid(n), VoxelRadianceOptions{}, "test/radiance");
    Volume v(size_t(n) * n * n, glm::vec4(0.0f));
    for (int z = 0; z < int(n); ++z)
        for (int y = 0; y < int(n); ++y)
            for (int x = 20; x < 24; ++x)
                v[idx(n, x, y, z)] = glm::vec4(0.0f, 0.0f, 0.0f, 1.0f);
    uploadAndFilter(*m_ctx, rad, v);
    ConeRunner runner(*m_ctx, rad);
    const VoxelGrid& g = rad.grid();
    const float v0 = g.voxelSize();
    const glm::vec3 origin = g.gridToWorld(glm::vec3(8.0f, 16.0f, 16.0f));
    const float lambda = 1.0f / (12.0f * v0);  // f = 1/2 at the wall's front face
    const std::vector<glm::vec4> out = runner.run({
        runner.trace(origin, {1, 0, 0}, 0.0f, runner.params(0.25f, 100.0f, 0.0f), 1),
        runner.trace(origin, {1, 0, 0}, 0.0f, runner.params(0.25f, 100.0f, lambda), 1),
        runner.trace(origin, {1, 0, 0}, 0.0f, runner.params(0.5f, 100.0f, lambda), 1),
        runner.trace(origin, {0, 1, 0}, 0.0f, runner.params(0.25f, 100.0f, lambda), 1),
    });
    // Reference: visibility = exp(integral of ln(1 - f(t) a(t)) dt / v0) through the trilinear
    // profile of the wall (a = 1 on cell centres 20.5..23.5, linear ramps one voxel wide).
    double logVis = 0.0;
    const int steps = 20000;
    for (int i = 0; i < steps; ++i) {
        const double x = 19.5 + 5.0 * (i + 0.5) / steps;  // grid units
        const double a = std::clamp(std::min(x - 19.5, 24.5 - x), 0.0, 1.0);
        const double f = 1.0 / (1.0 + double(lambda) * (x - 8.0) * v0);
        logVis += std::log(1.0 - f * a) * (5.0 / steps);
    }
    const float expected = float(std::exp(logVis));
    EXPECT_NEAR(out[0].a, 0.0f, 0.01f);
    EXPECT_GT(expected, 0.05f);
    EXPECT_NEAR(out[1].a, expected, 0.02f);
    EXPECT_NEAR(out[2].a, expected, 0.03f);  // step factor 0.5
    EXPECT_EQ(out[3].a, 1.0f);               // nothing along +y
}

// Not a test of correctness: prints the filter time for N = 64 and 128 (run with
// --gtest_also_run_disabled_tests --gtest_filter=*FilterTiming*).
TEST_F(GpuVoxelRadiance, DISABLED_FilterTiming) {
    for (uint32_t n : {64u, 128u})
        for (bool aniso : {true, false}) {
            VoxelRadianceOptions o;
            o.anisotropic = aniso;
            VoxelRadiance rad(*m_ctx, testGrid(n), o, "test/radiance");
            uploadAndFilter(*m_ctx, rad, Volume(size_t(n) * n * n, glm::vec4(0.5f)));
            double best = 1e30;
            for (int i = 0; i < 3; ++i) {
                const auto t0 = std::chrono::steady_clock::now();
                m_ctx->submitAndWait([&](VkCommandBuffer cmd) { rad.filter(cmd); });
                const auto t1 = std::chrono::steady_clock::now();
                best = std::min(best, std::chrono::duration<double, std::milli>(t1 - t0).count());
            }
            std::printf("filter N=%u %s: %.2f ms (best of 3, submit+wait), memory %.2f MiB\n", n,
                        aniso ? "anisotropic" : "isotropic", best,
                        double(rad.memoryBytes()) / (1024.0 * 1024.0));
        }
}

}  // namespace
}  // namespace gilab
