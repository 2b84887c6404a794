// `vct` (Crassin et al. 2011): light injection energy, parameter validation and the rendered
// indirect layer on the Cornell box spot variant (techniques/vct/README.md). Small: 32^3 grids,
// 64^2 images.
#include <cmath>
#include <memory>
#include <string>

#include <gtest/gtest.h>

#include "techniques/vct/tests/vct_test_rig.h"
#include "tests/gpu_test_fixture.h"

#include "core/gpu/gpu_scene.h"
#include "core/image/image.h"
#include "core/passes/shared_passes.h"
#include "core/scene/scene_loader.h"
#include "core/technique/frame_harness.h"
#include "core/technique/registry.h"
#include "core/util/error.h"
#include "core/voxel/voxel_radiance.h"
#include "core/voxel/voxelizer.h"
#include "techniques/vct/light_injection.h"
#include "techniques/vct/vct.h"

namespace gilab {
namespace {

constexpr double kPi = 3.14159265358979323846;

using test::cornell;
using test::vctParams;
using test::VctRig;

glm::dvec3 totalFlux(const std::vector<vct::GpuPhoton>& photons, bool validOnly) {
    glm::dvec3 sum(0.0);
    for (const vct::GpuPhoton& p : photons)
        if (!validOnly || p.positionValid.w > 0.5f) sum += glm::dvec3(p.flux);
    return sum;
}

/** Runs vct through the frame harness and returns its layers (also usable for the octree). */
std::vector<ImageLayer> renderVct(vk::Context& vk, const Scene& scene, const ParamSet& params) {
    FrameHarness h(vk, scene, "vct", params, defaultSharedParams());
    EXPECT_TRUE(h.support().supported) << h.support().reason;
    h.setup();
    h.renderFrame();
    return h.readLayers();
}

const Image& layer(const std::vector<ImageLayer>& layers, const std::string& name) {
    for (const ImageLayer& l : layers)
        if (l.name == name) return l.image;
    throw Error("no layer " + name);
}

using GpuVct = test::ValidatedGpuTest;

}  // namespace

TEST(CpuVct, ParameterErrorsNameTheKey) {
    ParamSet p = TechniqueRegistry::instance().defaultParams("vct");
    const std::pair<const char*, const char*> bad[] = {
        {"voxel_resolution", "16"}, {"storage", "sparse"},         {"diffuse_cones", "17"},
        {"step_factor", "nan"},     {"diffuse_aperture_deg", "0"}, {"light_map_resolution", "-1"}};
    for (const auto& [key, value] : bad) {
        try {
            p.set(key, value);
            ADD_FAILURE() << key << "=" << value << " accepted";
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
        }
    }
    EXPECT_EQ(TechniqueRegistry::instance().get("vct").indirectBounces, 1);
    // Emitters are injected through hemicube light-view maps of the shared emitter samples
    EXPECT_TRUE(TechniqueRegistry::instance().get("vct").supports.emissiveSurfaces);
}

TEST(CpuVct, EmittersAreSupported) {
    const Scene scene = cornell("");  // the default variant lights the box with an area light
    auto technique = TechniqueRegistry::instance().create("vct");
    const SupportResult s = technique->checkSupport(scene, vctParams({}));
    EXPECT_TRUE(s.supported) << s.reason;
}

TEST(CpuVct, LightViewsOfAPointLightCoverTheSphere) {
    const Scene scene = cornell("point");
    const VoxelGrid grid(scene.caps.bounds, 32);
    const auto views = vct::buildLightViews(scene, grid);
    ASSERT_EQ(views.size(), 6u);
    glm::dvec3 flux(0.0);
    for (const auto& v : views)
        flux += vct::lightViewFluxBound(v);
    const glm::dvec3 expected = 4.0 * kPi * glm::dvec3(scene.lights[0].intensity);
    for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(flux[c], expected[c], 1e-9 * expected[c]);
}

TEST(CpuVct, VoxelResolutionMustBeAPowerOfTwo) {
    vk::Context vk;
    try {
        VctRig rig(vk, cornell("spot"), vctParams({{"voxel_resolution", "48"}}));
        FAIL() << "48 accepted";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("voxel_resolution"), std::string::npos);
    }
}

// Every texel's flux, hit or miss, sums to the light's whole flux: 4 pi I for a point light.
TEST_F(GpuVct, PointLightPhotonsCarryFourPiI) {
    VctRig rig(*m_ctx, cornell("point"), vctParams({{"light_map_resolution", "64"}}));
    auto& inj = *rig.technique.injection();
    EXPECT_EQ(inj.photonCount(), 6u * 64u * 64u);
    const std::vector<vct::GpuPhoton> photons = inj.readPhotons();
    const glm::dvec3 all = totalFlux(photons, false);
    const glm::dvec3 expected = 4.0 * kPi * glm::dvec3(rig.scene.lights[0].intensity);
    for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(all[c], expected[c], 1e-3 * expected[c]) << "channel " << c;
    // The box is open at the front: most but not all photons hit it
    const glm::dvec3 hit = totalFlux(photons, true);
    EXPECT_GT(hit.x, 0.5 * all.x);
    EXPECT_LT(hit.x, all.x);
}

// A spot's photons carry I * integral of the glTF falloff: 2 pi [(1 - cos_i) + (cos_i - cos_o)/3].
TEST_F(GpuVct, SpotPhotonsCarryTheConeFlux) {
    VctRig rig(*m_ctx, cornell("spot"), vctParams({{"light_map_resolution", "256"}}));
    const Light& l = rig.scene.lights[0];
    const double ci = std::cos(double(l.innerConeRad)), co = std::cos(double(l.outerConeRad));
    const glm::dvec3 expected =
        2.0 * kPi * ((1.0 - ci) + (ci - co) / 3.0) * glm::dvec3(l.intensity);
    const glm::dvec3 all = totalFlux(rig.technique.injection()->readPhotons(), false);
    for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(all[c], expected[c], 2e-3 * expected[c]) << "channel " << c;
}

// The splat loses nothing: the voxels' flux sums to the photons' (valid hits), and lands in
// covered voxels.
TEST_F(GpuVct, SplatConservesTheInjectedFlux) {
    VctRig rig(*m_ctx, cornell("spot"), vctParams({}));
    auto& inj = *rig.technique.injection();
    const glm::dvec3 photons = totalFlux(inj.readPhotons(), true);
    const std::vector<glm::vec3> voxels = inj.readVoxelFlux();
    glm::dvec3 sum(0.0);
    for (const glm::vec3& v : voxels)
        sum += glm::dvec3(v);
    ASSERT_GT(photons.x, 0.0);
    for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(sum[c], photons[c], 1e-4 * photons[c]) << "channel " << c;

    // Radiance base: rgb = a albedo / pi * flux / v0^2, finite and non-negative
    const std::vector<glm::vec4> base = rig.technique.radiance()->readLevel(0, 0);
    const float v0 = rig.technique.grid().voxelSize();
    double radianceTimesArea = 0.0;
    for (size_t i = 0; i < base.size(); ++i) {
        ASSERT_TRUE(std::isfinite(base[i].r) && base[i].r >= 0.0f) << i;
        radianceTimesArea += double(base[i].r) * v0 * v0 * kPi;
    }
    // Sum of a albedo flux over voxels: between the darkest and brightest albedo's share
    EXPECT_GT(radianceTimesArea, 0.1 * photons.x);
    EXPECT_LT(radianceTimesArea, 1.0 * photons.x);
}

TEST_F(GpuVct, CornellSpotIndirectIsFiniteAndBleedsColour) {
    const Scene scene = cornell("spot");
    const auto layers = renderVct(*m_ctx, scene, vctParams({{"ao", "true"}}));
    const Image& indirect = layer(layers, "indirect");
    const Image& albedo = layer(layers, "albedo");
    const FiniteStats stats = countNonFinite(indirect);
    EXPECT_TRUE(stats.allFinite());
    double total = 0.0;
    glm::dvec3 left(0.0), right(0.0);
    const int w = indirect.width(), h = indirect.height();
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
            glm::vec3 v(indirect.at(x, y, 0), indirect.at(x, y, 1), indirect.at(x, y, 2));
            ASSERT_GE(std::min({v.r, v.g, v.b}), 0.0f) << x << "," << y;
            total += v.r + v.g + v.b;
            // White surfaces only (floor, ceiling, back wall): their indirect colour is bleeding
            const glm::vec3 a(albedo.at(x, y, 0), albedo.at(x, y, 1), albedo.at(x, y, 2));
            if (a.r <= 0.0f || std::abs(a.r - a.g) > 0.05f * a.r) continue;
            if (x < w / 3) left += glm::dvec3(v);
            if (x >= w - w / 3) right += glm::dvec3(v);
        }
    }
    EXPECT_GT(total, 0.0);
    ASSERT_GT(left.g, 0.0);
    ASSERT_GT(right.g, 0.0);
    const double leftRatio = left.r / left.g, rightRatio = right.r / right.g;
    std::printf("indirect r/g near the left (red) wall %.3f, near the right (green) wall %.3f\n",
                leftRatio, rightRatio);
    EXPECT_GT(leftRatio, 1.2 * rightRatio);

    // AO debug view in [0, 1], darker somewhere (corners) than elsewhere
    const Image& ao = layer(layers, "debug_ao");
    float lo = 1.0f, hi = 0.0f;
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
            if (albedo.at(x, y, 0) <= 0.0f) continue;
            lo = std::min(lo, ao.at(x, y, 0));
            hi = std::max(hi, ao.at(x, y, 0));
        }
    }
    EXPECT_GE(lo, 0.0f);
    EXPECT_LE(hi, 1.0f);
    EXPECT_LT(lo, hi - 0.1f);
}

TEST_F(GpuVct, PassesAreNamedAndIsotropicWorks) {
    const Scene scene = cornell("spot");
    FrameHarness h(*m_ctx, scene, "vct", vctParams({{"anisotropic", "false"}}),
                   defaultSharedParams());
    const SetupTiming setup = h.setup();
    std::vector<std::string> names;
    for (const auto& p : setup.passes)
        names.push_back(p.name);
    for (const char* expected : {"voxelize", "voxel_resolve", "vct/inject", "vct/filter"})
        EXPECT_NE(std::find(names.begin(), names.end(), expected), names.end()) << expected;
    const FrameTiming frame = h.renderFrame();
    bool traced = false;
    for (const auto& p : frame.passes)
        traced = traced || p.name == "vct/trace";
    EXPECT_TRUE(traced);
    const auto layers = h.readLayers();
    const Image& indirect = layer(layers, "indirect");
    EXPECT_TRUE(countNonFinite(indirect).allFinite());
    double total = 0.0;
    for (float v : indirect.values())
        total += v;
    EXPECT_GT(total, 0.0);
}

}  // namespace gilab
