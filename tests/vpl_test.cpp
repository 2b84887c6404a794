// The shared VPL module (core/vpl, docs/vpl.md): sampling and paraboloid mathematics (CPU mirror
// of shaders/common/vpl.glsl), the paraboloid maps, the RSM's VPL flux and the VPL gathering
// against closed forms. GPU tests run with validation on and fail on any message.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <map>
#include <set>

#include <glm/glm.hpp>
#include "tests/gpu_test_fixture.h"

#include "core/gpu/gpu_scene.h"
#include "core/passes/shared_passes.h"
#include "core/scene/mesh_builder.h"
#include "core/scene/scene.h"
#include "core/vk/buffer.h"
#include "core/vk/context.h"
#include "core/vpl/paraboloid_maps.h"
#include "core/vpl/rsm.h"
#include "core/vpl/vpl.h"
#include "core/vpl/vpl_math.h"
#include "core/vpl/vpl_shading.h"

namespace gilab {
namespace {

constexpr float kPi = 3.14159265358979f;
constexpr uint32_t kSize = 64;

// ---------------------------------------------------------------------------------------------
// Mathematics (CPU mirror)
// ---------------------------------------------------------------------------------------------

TEST(CpuVplMath, ParaboloidMappingRoundTrips) {
    float worst = 0.0f;
    for (int i = 0; i <= 64; ++i) {
        for (int j = 0; j < 64; ++j) {
            const float theta = 0.5f * kPi * float(i) / 64.0f;  // 0 .. 90 deg from the axis
            const float phi = 2.0f * kPi * float(j) / 64.0f;
            const glm::vec3 d(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi),
                              std::cos(theta));
            const glm::vec2 p = vpl::paraboloidProject(d);
            ASSERT_LE(glm::length(p), 1.0f + 1e-6f);
            worst = std::max(worst, glm::length(vpl::paraboloidDirection(p) - d));
            const glm::vec2 back = vpl::paraboloidProject(vpl::paraboloidDirection(p));
            worst = std::max(worst, glm::length(back - p));
        }
    }
    EXPECT_LT(worst, 1e-5f);
}

TEST(CpuVplMath, SolidAngleDensityCoversTheHemisphere) {
    // Integral of 4 / (1 + r^2)^2 over the unit disk = 2 pi (a midpoint rule on 1024^2 cells).
    const int n = 1024;
    double sum = 0.0;
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
            const glm::vec2 p((x + 0.5f) / n * 2.0f - 1.0f, (y + 0.5f) / n * 2.0f - 1.0f);
            if (glm::dot(p, p) <= 1.0f) sum += vpl::paraboloidSolidAngleDensity(p);
        }
    sum *= (2.0 / n) * (2.0 / n);
    EXPECT_NEAR(sum, 2.0 * kPi, 5e-3);
}

TEST(CpuVplMath, FrameIsOrthonormalWithTheNormalAsZ) {
    for (const glm::vec3 n : {glm::vec3(0, 0, 1), glm::vec3(0, 0, -1), glm::vec3(1, 0, 0),
                              glm::normalize(glm::vec3(0.3f, -0.2f, -0.93f)),
                              glm::normalize(glm::vec3(1e-7f, 0.0f, -1.0f))}) {
        const glm::mat3 f = vpl::frame(n);
        const glm::mat3 i = f * glm::transpose(f);
        for (int a = 0; a < 3; ++a)
            for (int b = 0; b < 3; ++b)
                EXPECT_NEAR(i[a][b], a == b ? 1.0f : 0.0f, 1e-5f);
        const glm::vec3 z = f * n;
        EXPECT_NEAR(z.z, 1.0f, 1e-5f);
    }
}

/** Chi-square of `points` over 8 equal-area rings x 8 sectors of the unit disk. */
double diskChiSquare(const std::vector<glm::vec2>& points) {
    std::vector<double> cells(64, 0.0);
    for (const glm::vec2& p : points) {
        const float r2 = glm::dot(p, p);
        if (r2 > 1.0f + 1e-6f) return 1e30;  // outside the disk
        const int ring = std::min(7, int(r2 * 8.0f));
        float phi = std::atan2(p.y, p.x);
        if (phi < 0.0f) phi += 2.0f * kPi;
        const int sector = std::min(7, int(phi / (2.0f * kPi) * 8.0f));
        cells[size_t(ring * 8 + sector)] += 1.0;
    }
    const double expected = double(points.size()) / 64.0;
    double chi = 0.0;
    for (double c : cells)
        chi += (c - expected) * (c - expected) / expected;
    return chi;
}

// Aranha et al. §III-C samples the paraboloid's disk uniformly. The statistic is chi-square
// with 63 degrees of freedom: 99.9 % of uniform random sets stay below 103.4; the fixed
// Hammersley set must, and a map that is not area-preserving (r = u) must not.
TEST(CpuVplMath, ConcentricDiskSamplesCoverTheDiskUniformly) {
    for (uint32_t n : {256u, 1024u, 4096u}) {
        std::vector<glm::vec2> uniform, biased;
        for (uint32_t k = 0; k < n; ++k) {
            const glm::vec2 u = vpl::hammersley(k, n);
            uniform.push_back(vpl::concentricDisk(u));
            const float phi = 2.0f * kPi * u.y;
            biased.push_back(u.x * glm::vec2(std::cos(phi), std::sin(phi)));
        }
        const double chi = diskChiSquare(uniform);
        std::printf("n = %u: chi-square %.1f (uniform), %.1f (r = u)\n", n, chi,
                    diskChiSquare(biased));
        EXPECT_LT(chi, 103.4) << n;
        EXPECT_GT(diskChiSquare(biased), 103.4) << n;
    }
}

TEST(CpuVplMath, DiskSampleWeightHasMeanOne) {
    const uint32_t n = 4096;
    double sum = 0.0;
    for (uint32_t k = 0; k < n; ++k)
        sum += vpl::diskSampleWeight(vpl::concentricDisk(vpl::hammersley(k, n)));
    EXPECT_NEAR(sum / n, 1.0, 0.01);
}

TEST(CpuVplMath, HammersleyIsEquationOne) {
    EXPECT_EQ(vpl::hammersley(0, 8), glm::vec2(0.0f, 0.0f));
    EXPECT_EQ(vpl::hammersley(1, 8), glm::vec2(0.125f, 0.5f));
    EXPECT_EQ(vpl::hammersley(3, 8), glm::vec2(0.375f, 0.75f));
    EXPECT_EQ(vpl::hammersley(6, 8), glm::vec2(0.75f, 0.375f));
}

// Interleaved subsets of the Hammersley set (issue 29): every mode is a partition into equal
// shares; blocks and fold give every subset points in each quarter of the RSM in x and in y,
// fold gives one point of every elementary box of `stride` points to each subset (any aspect
// ratio), and modulo, the version before, puts a whole subset into one strip of height 1/stride.
TEST(CpuVplMath, InterleaveSubsetsPartitionTheSetAndSpreadOverTheRsm) {
    const uint32_t n = 256, stride = 16;
    for (uint32_t mode = 0; mode < 3; ++mode) {
        std::vector<uint32_t> count(stride, 0);
        std::vector<std::vector<int>> xq(stride, std::vector<int>(4, 0)), yq = xq;
        for (uint32_t k = 0; k < n; ++k) {
            const uint32_t s = vpl::interleaveSubset(k, n, stride, 0, mode);
            ASSERT_LT(s, stride);
            ++count[s];
            const glm::vec2 u = vpl::hammersley(k, n);
            ++xq[s][int(u.x * 4.0f)];
            ++yq[s][int(u.y * 4.0f)];
        }
        for (uint32_t s = 0; s < stride; ++s) {
            EXPECT_EQ(count[s], n / stride) << "mode " << mode;
            if (mode == 2) continue;
            for (int q = 0; q < 4; ++q) {
                EXPECT_EQ(xq[s][q], 4) << "mode " << mode << " subset " << s;
                EXPECT_EQ(yq[s][q], 4) << "mode " << mode << " subset " << s;
            }
        }
    }
    // fold: every elementary box of 2^a x 2^(4-a) cells (16 points) holds each subset once.
    for (int a = 0; a <= 4; ++a) {
        std::map<std::pair<int, int>, std::vector<int>> boxes;
        for (uint32_t k = 0; k < n; ++k) {
            const glm::vec2 u = vpl::hammersley(k, n);
            const std::pair<int, int> cell{int(u.x * float(n >> 4 >> a)), int(u.y * float(1 << a))};
            boxes[cell].push_back(int(vpl::interleaveSubset(k, n, stride, 3, 0)));
        }
        for (auto& [cell, subsets] : boxes) {
            std::sort(subsets.begin(), subsets.end());
            ASSERT_EQ(subsets.size(), stride);
            for (uint32_t s = 0; s < stride; ++s)
                EXPECT_EQ(subsets[s], int(s)) << "a " << a;
        }
    }
    // modulo: subset 0 lies in one strip of y.
    float lo = 1.0f, hi = 0.0f;
    for (uint32_t k = 0; k < n; k += stride) {
        lo = std::min(lo, vpl::hammersley(k, n).y);
        hi = std::max(hi, vpl::hammersley(k, n).y);
    }
    EXPECT_LT(hi - lo, 1.0f / float(stride));
    // A stride that is no power of two (I = 3) falls back to blocks: still a partition.
    std::vector<uint32_t> nine(9, 0);
    for (uint32_t k = 0; k < n; ++k)
        ++nine[vpl::interleaveSubset(k, n, 9, 1, 0)];
    for (uint32_t c : nine) {
        EXPECT_GE(c, 24u);
        EXPECT_LE(c, 32u);
    }
}

// Issue 43: every set is spread, whatever its size. ssvp's second-bounce disk sets hold N2 / C = 32
// VPLs, too few for blocks at I = 4 (L = 1): `blocks` fell back to `modulo`'s strips there. Now,
// for I = 2, 3, 4 and sets of 32 to 1024 VPLs, fold and blocks (and its shifted rows at L = 1)
// give every subset of two or more points points in both halves of the set in x and in y, and
// stay a partition into shares that differ by at most one block; modulo, at even strides, never
// does.
TEST(CpuVplMath, InterleaveSubsetsSpreadEverySetSize) {
    for (uint32_t stride : {4u, 9u, 16u}) {
        for (uint32_t n : {32u, 48u, 64u, 128u, 256u, 1024u}) {
            for (uint32_t mode = 0; mode < 3; ++mode) {
                for (uint32_t rotation : {0u, 1u, 5u}) {
                    std::vector<std::vector<uint32_t>> members(stride);
                    for (uint32_t k = 0; k < n; ++k)
                        members[vpl::interleaveSubset(k, n, stride, rotation, mode)].push_back(k);
                    uint32_t narrow = 0;
                    size_t fewest = n, most = 0;
                    for (const std::vector<uint32_t>& m : members) {
                        fewest = std::min(fewest, m.size());
                        most = std::max(most, m.size());
                        std::set<int> xHalf, yHalf;
                        for (uint32_t k : m) {
                            const glm::vec2 u = vpl::hammersley(k, n);
                            xHalf.insert(int(u.x * 2.0f));
                            yHalf.insert(int(u.y * 2.0f));
                        }
                        if (m.size() >= 2 && (xHalf.size() < 2 || yHalf.size() < 2)) ++narrow;
                    }
                    // Equal shares up to one block (one point when L = 1).
                    EXPECT_LE(most - fewest, vpl::interleaveBlock(n, stride))
                        << stride << " " << n << " " << mode;
                    if (mode == 2 && stride % 2 == 0)  // strips of y (k, k + stride: same low bits)
                        EXPECT_GT(narrow, 0u) << "modulo, stride " << stride << " n " << n;
                    else if (mode != 2)
                        EXPECT_EQ(narrow, 0u) << "mode " << mode << " stride " << stride << " n "
                                              << n << " rotation " << rotation;
                }
            }
        }
    }
}

// ---------------------------------------------------------------------------------------------
// GPU
// ---------------------------------------------------------------------------------------------

Material diffuse(float albedo) {
    Material m;
    m.baseColorFactor = glm::vec4(glm::vec3(albedo), 1.0f);
    return m;
}

/** The plane y = 0 (albedo 0.5), [-h, h]^2, facing up; optionally a square roof at y = 1. */
Scene planeScene(float h = 6.0f, bool roof = false) {
    Scene s;
    s.name = "test_plane";
    s.sourcePath = "<test>";
    s.materials.push_back(diffuse(0.5f));
    appendQuad(s, {-h, 0.0f, -h}, {h, 0.0f, -h}, {h, 0.0f, h}, {-h, 0.0f, h}, {0, 1, 0}, 0);
    if (roof)
        appendQuad(s, {-0.5f, 1.0f, -0.5f}, {0.5f, 1.0f, -0.5f}, {0.5f, 1.0f, 0.5f},
                   {-0.5f, 1.0f, 0.5f}, {0, -1, 0}, 0);
    s.settings.width = int(kSize);
    s.settings.height = int(kSize);
    return s;
}

Camera topCamera(float height = 3.0f) {
    Camera c;
    c.position = {0.0f, height, 0.0f};
    c.target = {0.0f, 0.0f, 0.0f};
    c.up = {0.0f, 0.0f, -1.0f};
    c.vfovRad = 1.0471976f;
    return c;
}

vk::Buffer storageBuffer(vk::Context& ctx, VkDeviceSize bytes, const std::string& name) {
    return vk::Buffer(ctx, bytes,
                      VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT |
                          VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                      vk::MemoryUsage::DeviceLocal, name);
}

using GpuVplTest = test::ValidatedGpuTest;

// A map seen from above the plane, partly blocked by a roof: every stored texel is a point of the
// scene (on y = 0 or the roof), its radial distance is its distance from the eye, and its
// direction projects back into the same texel (the inverse mapping the shaders use).
TEST_F(GpuVplTest, ParaboloidMapTexelsAreExactScenePointsThatProjectBack) {
    Scene scene = planeScene(6.0f, true);
    scene.computeCaps();
    vk::GpuScene gpuScene(*m_ctx, scene);
    GpuVplCluster cluster;
    const glm::vec3 eye(0.2f, 2.0f, 0.1f), axis(0.0f, -1.0f, 0.0f);
    cluster.position = glm::vec4(eye, 1.0f);
    cluster.normal = glm::vec4(axis, 1.0f);
    cluster.mean = glm::vec4(eye, 1.0f);
    vk::Buffer clusters = storageBuffer(*m_ctx, sizeof(cluster), "test/clusters");
    clusters.upload(&cluster, sizeof(cluster));
    ParaboloidSettings ps;
    ps.resolution = 64;
    ps.layers = 1;
    ps.far = 40.0f;
    ParaboloidMaps maps(*m_ctx, gpuScene, clusters, ps, "test");
    m_ctx->submitAndWait([&](VkCommandBuffer cmd) { maps.record(cmd); });
    const std::vector<float> pos = maps.position().readbackFloat(*m_ctx);
    const glm::mat3 frame = vpl::frame(axis);
    int covered = 0, roof = 0, badPlane = 0, badDistance = 0, badTexel = 0;
    for (uint32_t y = 0; y < 64; ++y) {
        for (uint32_t x = 0; x < 64; ++x) {
            const float* t = &pos[(y * 64 + x) * 4];
            if (t[3] <= 0.0f) continue;
            ++covered;
            const glm::vec3 p(t[0], t[1], t[2]);
            if (std::abs(p.y - 1.0f) < 1e-4f)
                ++roof;
            else if (std::abs(p.y) > 1e-4f)
                ++badPlane;
            if (std::abs(glm::length(p - eye) - t[3]) > 1e-4f * t[3]) ++badDistance;
            const glm::vec2 q = vpl::paraboloidProject(glm::normalize(frame * (p - eye)));
            const glm::vec2 texel = (0.5f * q + 0.5f) * 64.0f;
            if (std::abs(texel.x - (x + 0.5f)) > 0.51f || std::abs(texel.y - (y + 0.5f)) > 0.51f)
                ++badTexel;
        }
    }
    std::printf("paraboloid 64^2: %d texels covered, %d on the roof\n", covered, roof);
    EXPECT_GT(covered, int(0.45f * kPi * 32 * 32));  // the plane: ~54 % of the disk
    EXPECT_GT(roof, 100);                            // the roof occludes the plane's centre
    EXPECT_EQ(badPlane, 0);
    EXPECT_EQ(badDistance, 0);
    EXPECT_EQ(badTexel, 0);
    // The texel straight below the eye sees the roof, not the plane behind it.
    EXPECT_NEAR(pos[(32 * 64 + 32) * 4 + 1], 1.0f, 1e-4f);
}

struct GatherRig {
    std::unique_ptr<vk::GpuScene> gpuScene;
    std::unique_ptr<SharedPasses> passes;
    vk::Buffer vpls, clusters;
    std::unique_ptr<VplShading> shading;
};

GatherRig gatherRig(vk::Context& ctx, Scene scene, const std::vector<GpuVpl>& vpls) {
    scene.computeCaps();
    GatherRig r;
    r.gpuScene = std::make_unique<vk::GpuScene>(ctx, scene);
    r.passes = std::make_unique<SharedPasses>(ctx, *r.gpuScene, kSize, kSize);
    ctx.submitAndWait([&](VkCommandBuffer cmd) { r.passes->record(cmd, topCamera()); });
    r.vpls = storageBuffer(ctx, vpls.size() * sizeof(GpuVpl), "test/vpls");
    r.vpls.upload(vpls.data(), vpls.size() * sizeof(GpuVpl));
    r.clusters = storageBuffer(ctx, sizeof(GpuVplCluster), "test/clusters");
    r.shading =
        std::make_unique<VplShading>(ctx, r.passes->gbuffer(), r.vpls, r.clusters, nullptr, "test");
    return r;
}

std::vector<float> gather(vk::Context& ctx, GatherRig& r, const VplShadingSettings& s,
                          uint32_t count) {
    r.shading->setSettings(s);
    ctx.submitAndWait([&](VkCommandBuffer cmd) { r.shading->recordGather(cmd, count, count); });
    return r.shading->irradiance().readbackFloat(ctx);
}

GpuVpl vpl(glm::vec3 p, glm::vec3 n, glm::vec3 flux) {
    GpuVpl v;
    v.position = glm::vec4(p, 1.0f);
    v.normal = glm::vec4(glm::normalize(n), -1.0f);
    v.flux = glm::vec4(flux, 1.0f);
    return v;
}

// One VPL facing the plane, no occluder: E = flux cos(theta) cos(sigma) / (pi d^2) exactly, and
// with a clamp distance d_min: flux cos cos / (pi max(d, d_min)^2), the removed part measured.
TEST_F(GpuVplTest, SingleVplMatchesThePointLightIrradianceWithinTheClamp) {
    const glm::vec3 p(0.3f, 0.4f, -0.2f), n = glm::normalize(glm::vec3(0.2f, -1.0f, 0.1f));
    const glm::vec3 flux(2.0f, 3.0f, 4.0f);
    GatherRig rig = gatherRig(*m_ctx, planeScene(), {vpl(p, n, flux)});
    const std::vector<float> pos = rig.passes->gbuffer().position.readbackFloat(*m_ctx);
    VplShadingSettings s;
    s.interleave = 1;
    s.blurRadius = 0;
    for (float dMin : {0.0f, 0.6f}) {
        s.clampDistance = dMin;
        const std::vector<float> e = gather(*m_ctx, rig, s, 1);
        const VplClampStats stats = rig.shading->readClampStats();
        float worst = 0.0f;
        int clampedPixels = 0, checked = 0;
        for (uint32_t i = 0; i < kSize * kSize; ++i) {
            if (pos[i * 4 + 3] < 0.5f) continue;
            const glm::vec3 x(pos[i * 4], pos[i * 4 + 1], pos[i * 4 + 2]);
            const glm::vec3 d = p - x;
            const float dist = glm::length(d);
            const glm::vec3 l = d / dist;
            const float g = std::max(l.y, 0.0f) * std::max(glm::dot(n, -l), 0.0f) / kPi;
            const glm::vec3 want = flux * g / std::max(dist * dist, dMin * dMin);
            clampedPixels += dist < dMin && g > 0.0f;
            for (int c = 0; c < 3; ++c) {
                ASSERT_TRUE(std::isfinite(e[i * 4 + c]));
                worst =
                    std::max(worst, std::abs(e[i * 4 + c] - want[c]) / std::max(want[c], 1e-3f));
            }
            ++checked;
        }
        std::printf("d_min %.2f: %d pixels, max relative error %.2g, %d clamped, removed %.3f %%\n",
                    dMin, checked, worst, clampedPixels, stats.removedPercent());
        EXPECT_GT(checked, int(kSize * kSize / 2));
        EXPECT_LT(worst, 1e-3f);
        if (dMin == 0.0f) {
            EXPECT_EQ(stats.removedIrradiance, 0.0);  // no clamp, nothing removed
        } else {
            EXPECT_GT(clampedPixels, 10);
            EXPECT_GT(stats.removedIrradiance, 0.0);
        }
    }
}

// VPLs on the receiving surface, a hair above it, and grazing it: finite, non-negative
// irradiance everywhere (Aranha et al. put second-bounce VPLs on surfaces next to receivers).
TEST_F(GpuVplTest, VplsOnOrNearTheSurfaceGiveNoNaN) {
    std::vector<GpuVpl> vpls;
    for (float h : {0.0f, 1e-30f, 1e-7f, 1e-3f})
        for (glm::vec3 n : {glm::vec3(0, 1, 0), glm::vec3(0, -1, 0), glm::vec3(1, 0, 0)})
            vpls.push_back(vpl({0.05f * float(vpls.size()), h, 0.0f}, n, glm::vec3(1e3f)));
    GatherRig rig = gatherRig(*m_ctx, planeScene(), vpls);
    VplShadingSettings s;
    s.blurRadius = 2;
    for (float dMin : {0.0f, 0.05f}) {
        s.clampDistance = dMin;
        const std::vector<float> e = gather(*m_ctx, rig, s, uint32_t(vpls.size()));
        for (float v : e) {
            ASSERT_TRUE(std::isfinite(v)) << "d_min " << dMin;
            ASSERT_GE(v, 0.0f);
        }
        EXPECT_TRUE(std::isfinite(rig.shading->readClampStats().removedIrradiance));
    }
}

// A directional light straight down on the plane: the RSM's VPLs carry the reflected power,
// E x (lit area) x albedo, however many there are.
TEST_F(GpuVplTest, RsmVplFluxIsTheReflectedPower) {
    Scene scene = planeScene(2.0f);
    Light sun;
    sun.type = LightType::Directional;
    sun.direction = {0.0f, -1.0f, 0.0f};
    sun.intensity = glm::vec3(3.0f, 2.0f, 1.0f);
    sun.color = sun.intensity;
    scene.lights.push_back(sun);
    scene.computeCaps();
    vk::GpuScene gpuScene(*m_ctx, scene);
    SharedPasses passes(*m_ctx, gpuScene, kSize, kSize);
    ReflectiveShadowMap rsm(*m_ctx, gpuScene, passes.shadows().lightBuffer(), 256, "test");
    for (uint32_t n : {256u, 4096u}) {
        vk::Buffer buffer = storageBuffer(*m_ctx, n * sizeof(GpuVpl), "test/vpls");
        m_ctx->submitAndWait([&](VkCommandBuffer cmd) {
            rsm.record(cmd, passes.shadows().lights()[0], 0);
            rsm.recordVpls(cmd, buffer, 0, n);
        });
        const std::vector<GpuVpl> v = buffer.downloadVector<GpuVpl>(n);
        glm::dvec3 sum(0.0);
        for (const GpuVpl& x : v) {
            ASSERT_TRUE(std::isfinite(x.flux.x));
            sum += glm::dvec3(x.flux);
        }
        const glm::dvec3 want = glm::dvec3(sun.intensity) * 16.0 * 0.5;  // E A albedo
        std::printf("RSM %u VPLs: flux %.3f (want %.3f)\n", n, sum.x, want.x);
        EXPECT_NEAR(sum.x / want.x, 1.0, n >= 4096 ? 0.03 : 0.1);
        EXPECT_NEAR(sum.z / want.z, 1.0, n >= 4096 ? 0.03 : 0.1);
    }
}

}  // namespace
}  // namespace gilab
