// The `seed` parameter of the techniques with a fixed sampling pattern (docs/experiments.md,
// "Seeds"): cvgi rotates every face's ray set about its normal, ssvp and topovpl shift their
// Hammersley VPLs toroidally (a Cranley-Patterson rotation) and ssvp starts K-means elsewhere.
// Seed 0 is the pattern from before the parameter, bit for bit; another seed changes the image
// but not its energy much; the same seed gives the same image.
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "tests/gpu_test_fixture.h"

#include "core/scene/scene.h"
#include "core/scene/scene_loader.h"
#include "core/technique/frame_harness.h"
#include "core/technique/registry.h"
#include "core/vpl/vpl_math.h"
#include "techniques/cvgi/cvgi_setup.h"

namespace gilab {
namespace {

// ---------------------------------------------------------------------------------------------
// The patterns on the CPU

bool sameBits(float a, float b) {
    return std::memcmp(&a, &b, sizeof a) == 0;
}

TEST(CpuSeed, SeedZeroIsNoShiftAndOtherSeedsAreDistinctShiftsInTheUnitSquare) {
    EXPECT_EQ(vpl::cranleyPattersonShift(0), glm::vec2(0.0f));
    std::set<std::pair<float, float>> seen;
    for (uint32_t seed = 1; seed <= 1000; ++seed) {
        const glm::vec2 s = vpl::cranleyPattersonShift(seed);
        ASSERT_TRUE(s.x >= 0.0f && s.x < 1.0f && s.y >= 0.0f && s.y < 1.0f) << seed;
        seen.insert({s.x, s.y});
    }
    EXPECT_EQ(seen.size(), 1000u);
    EXPECT_EQ(vpl::cranleyPattersonShift(7), vpl::cranleyPattersonShift(7));  // deterministic
}

TEST(CpuSeed, ShiftedHammersleyIsTheSetModuloOneAndSeedZeroIsTheSetBitForBit) {
    const uint32_t n = 256;
    const glm::vec2 shift = vpl::cranleyPattersonShift(1);
    for (uint32_t k = 0; k < n; ++k) {
        const glm::vec2 u = vpl::hammersley(k, n), z = vpl::hammersley(k, n, glm::vec2(0.0f));
        ASSERT_TRUE(sameBits(u.x, z.x) && sameBits(u.y, z.y)) << k;
        const glm::vec2 v = vpl::hammersley(k, n, shift);
        ASSERT_TRUE(v.x >= 0.0f && v.x < 1.0f && v.y >= 0.0f && v.y < 1.0f) << k;
        // The toroidal distance to u + shift is 0 (up to float rounding).
        for (int c = 0; c < 2; ++c) {
            const float d = std::abs(v[c] - (u[c] + shift[c]));
            EXPECT_TRUE(d < 1e-6f || std::abs(d - 1.0f) < 1e-6f) << k << " " << c;
        }
    }
    // Still stratified: each of the n columns [k/n, (k+1)/n) holds exactly one shifted point.
    std::vector<int> column(n, 0);
    for (uint32_t k = 0; k < n; ++k)
        ++column[std::min(n - 1, uint32_t(vpl::hammersley(k, n, shift).x * float(n)))];
    for (uint32_t c = 0; c < n; ++c)
        EXPECT_EQ(column[c], 1) << c;
}

// cvgi's rays: rotation 0 is the set from before the parameter (its formula, recomputed here);
// a seed's rotation keeps every ray's cos theta (so the cosines still sum to rays / 2) and turns
// every azimuth by the same angle.
TEST(CpuSeed, CvgiSeedRotatesTheRaySetAboutTheFaceNormal) {
    EXPECT_EQ(cvgi::seedRotation(0), 0.0);
    const uint32_t rays = 64;
    const std::vector<glm::vec3> base = cvgi::hemisphereDirections(rays);
    const std::vector<glm::vec3> zero = cvgi::hemisphereDirections(rays, cvgi::seedRotation(0));
    const double turn = cvgi::seedRotation(3);
    ASSERT_GT(turn, 0.0);
    ASSERT_LT(turn, 1.0);
    const std::vector<glm::vec3> turned = cvgi::hemisphereDirections(rays, turn);
    double cosines = 0.0;
    for (uint32_t i = 0; i < rays; ++i) {
        for (int c = 0; c < 3; ++c)
            ASSERT_TRUE(sameBits(base[i][c], zero[i][c])) << i;
        // The formula before the parameter (cvgi_setup.cpp, before `seed`).
        uint32_t r = i;
        r = (r << 16) | (r >> 16);
        r = ((r & 0x55555555u) << 1) | ((r & 0xAAAAAAAAu) >> 1);
        r = ((r & 0x33333333u) << 2) | ((r & 0xCCCCCCCCu) >> 2);
        r = ((r & 0x0F0F0F0Fu) << 4) | ((r & 0xF0F0F0F0u) >> 4);
        r = ((r & 0x00FF00FFu) << 8) | ((r & 0xFF00FF00u) >> 8);
        const double cosTheta = 1.0 - (double(i) + 0.5) / double(rays);
        const double sinTheta = std::sqrt(std::max(0.0, 1.0 - cosTheta * cosTheta));
        const double phi = 2.0 * 3.14159265358979323846 * (double(r) * 0x1p-32);
        const glm::vec3 old(
            glm::dvec3(sinTheta * std::cos(phi), sinTheta * std::sin(phi), cosTheta));
        for (int c = 0; c < 3; ++c)
            EXPECT_TRUE(sameBits(old[c], base[i][c])) << i << " " << c;
        // Rotated about +z by `turn` turns.
        EXPECT_EQ(turned[i].z, base[i].z) << i;
        const double a = 2.0 * 3.14159265358979323846 * turn;
        const glm::dvec2 expected(std::cos(a) * base[i].x - std::sin(a) * base[i].y,
                                  std::sin(a) * base[i].x + std::cos(a) * base[i].y);
        EXPECT_NEAR(turned[i].x, expected.x, 1e-5) << i;
        EXPECT_NEAR(turned[i].y, expected.y, 1e-5) << i;
        cosines += turned[i].z;
    }
    EXPECT_NEAR(cosines, rays / 2.0, 1e-4);
}

// ---------------------------------------------------------------------------------------------
// The images

using GpuSeed = test::ValidatedGpuTest;

Scene spotBox(int size) {
    Scene scene = loadSceneFile(std::string(GILAB_SOURCE_DIR) + "/scenes/cornell_box.json", "spot");
    scene.settings.width = size;
    scene.settings.height = size;
    return scene;
}

/** The layers of one frame of `technique` with its defaults, `base` and `values` set. */
std::vector<ImageLayer> render(vk::Context& ctx, const Scene& scene, const std::string& technique,
                               const std::map<std::string, std::string>& base,
                               const std::map<std::string, std::string>& values) {
    ParamSet p = TechniqueRegistry::instance().defaultParams(technique);
    for (const auto& [k, v] : base)
        p.set(k, v);
    for (const auto& [k, v] : values)
        p.set(k, v);
    FrameHarness h(ctx, scene, technique, p, defaultSharedParams());
    EXPECT_TRUE(h.support().supported) << h.support().reason;
    h.setup();
    h.renderFrame();
    return h.readLayers();
}

const Image& layerOf(const std::vector<ImageLayer>& layers, const std::string& name) {
    for (const ImageLayer& l : layers)
        if (l.name == name) return l.image;
    ADD_FAILURE() << "no layer " << name;
    return layers.at(0).image;
}

/** Values of `a` and `b` (all layers) that differ bit for bit; -1 when the layers differ. */
long differingValues(const std::vector<ImageLayer>& a, const std::vector<ImageLayer>& b) {
    if (a.size() != b.size()) return -1;
    long n = 0;
    for (size_t i = 0; i < a.size(); ++i) {
        if (a[i].name != b[i].name || a[i].image.values().size() != b[i].image.values().size())
            return -1;
        const auto& va = a[i].image.values();
        const auto& vb = b[i].image.values();
        for (size_t j = 0; j < va.size(); ++j)
            n += sameBits(va[j], vb[j]) ? 0 : 1;
    }
    return n;
}

/** Pixels whose indirect RGB differs between `a` and `b`. */
long differingIndirectPixels(const std::vector<ImageLayer>& a, const std::vector<ImageLayer>& b) {
    const Image& ia = layerOf(a, "indirect");
    const Image& ib = layerOf(b, "indirect");
    long n = 0;
    for (int y = 0; y < ia.height(); ++y)
        for (int x = 0; x < ia.width(); ++x) {
            bool differs = false;
            for (int c = 0; c < 3; ++c)
                differs = differs || !sameBits(ia.at(x, y, c), ib.at(x, y, c));
            n += differs ? 1 : 0;
        }
    return n;
}

double indirectSum(const std::vector<ImageLayer>& layers) {
    const Image& image = layerOf(layers, "indirect");
    double sum = 0.0;
    for (int y = 0; y < image.height(); ++y)
        for (int x = 0; x < image.width(); ++x)
            for (int c = 0; c < 3; ++c)
                sum += image.at(x, y, c);
    return sum;
}

/**
 * The seed contract of `technique` on the spot-lit Cornell box at 32²: the defaults and an
 * explicit seed 0 give the same image bit for bit; seed 1 twice gives one image; seed 1 changes
 * some pixels, with its indirect energy within [lo, hi] of seed 0's.
 */
void checkSeedContract(vk::Context& ctx, const std::string& technique,
                       const std::map<std::string, std::string>& base, double lo, double hi) {
    const Scene scene = spotBox(32);
    const std::vector<ImageLayer> def = render(ctx, scene, technique, base, {});
    const std::vector<ImageLayer> zero = render(ctx, scene, technique, base, {{"seed", "0"}});
    const std::vector<ImageLayer> one = render(ctx, scene, technique, base, {{"seed", "1"}});
    const std::vector<ImageLayer> again = render(ctx, scene, technique, base, {{"seed", "1"}});
    EXPECT_EQ(differingValues(def, zero), 0);
    EXPECT_EQ(differingValues(one, again), 0);
    const long changed = differingIndirectPixels(zero, one);
    const double e0 = indirectSum(zero), e1 = indirectSum(one);
    std::printf("%s: seed 1 changes %ld of %d indirect pixels, energy %.6g / %.6g = %.4f\n",
                technique.c_str(), changed, 32 * 32, e1, e0, e0 > 0.0 ? e1 / e0 : 0.0);
    EXPECT_GT(changed, 0);
    ASSERT_GT(e0, 0.0);
    EXPECT_GE(e1 / e0, lo);
    EXPECT_LE(e1 / e0, hi);
}

// The energy bands: seed 1's indirect energy over seed 0's as measured on lavapipe (printed),
// with margin; seeds 1-8 were measured too, to see the spread the bands must not hide.

// The ray rotation moves which clusters a face's rays meet, not how much light there is:
// seeds 1-8 give 0.995-1.0004 of seed 0's energy (seed 1: 0.9992).
TEST_F(GpuSeed, CvgiSeedRotatesItsRaysAndKeepsItsEnergy) {
    checkSeedContract(*m_ctx, "cvgi", {{"voxel_resolution", "32"}, {"shadow_map_size", "512"}},
                      0.95, 1.05);
}

// ssvp's energy depends on where K-means starts: one frame's clusters fall into one of two
// modes, about 1.0 and 0.7 of seed 0's indirect energy here (0.4 and 1.0 of the first bounce
// alone, bounces = 1), and kmeans_seed alone does the same (kmeans_seed 3, 4, 6: 0.70; 2, 5:
// 1.0), so the spread is the technique's, not the shift's. Seed 1: 0.7027; seeds 1-5 0.70-1.13.
// The band takes both modes with 0.1 of margin.
TEST_F(GpuSeed, SsvpSeedShiftsItsVplsAndKMeansAndKeepsItsEnergy) {
    checkSeedContract(*m_ctx, "ssvp", {{"paraboloid_resolution", "64"}, {"rsm_resolution", "128"}},
                      0.6, 1.4);
}

// 256 VPLs on a 32² image: seeds 1-8 give 0.875-1.058 of seed 0's energy (seed 1: 0.9939).
TEST_F(GpuSeed, TopovplSeedShiftsItsVplsAndKeepsItsEnergy) {
    checkSeedContract(*m_ctx, "topovpl",
                      {{"voxel_resolution", "64"}, {"topology_cache", "off"}, {"vpls", "256"}}, 0.8,
                      1.25);
}

}  // namespace
}  // namespace gilab
