// `dvs` (deferred voxel shading, notes 003): per-voxel lighting against hand-computed values,
// shadow modes, the second bounce and end-to-end renders of the Cornell box. 32^3 grids, 64^2
// images. Gpu* tests run with validation on and fail on any validation message.
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <glm/glm.hpp>
#include "tests/gpu_test_fixture.h"

#include "core/gpu/gpu_scene.h"
#include "core/passes/shared_passes.h"
#include "core/scene/mesh_builder.h"
#include "core/scene/scene.h"
#include "core/scene/scene_loader.h"
#include "core/technique/frame_harness.h"
#include "core/technique/registry.h"
#include "core/util/error.h"
#include "core/vk/context.h"
#include "core/voxel/voxel_radiance.h"
#include "core/voxel/voxelizer.h"
#include "techniques/dvs/dvs_settings.h"
#include "techniques/dvs/voxel_lighting.h"

namespace gilab {
namespace {

constexpr float kPi = 3.14159265358979f;
constexpr float kAlbedo = 0.5f;

Material diffuse(glm::vec3 albedo) {
    Material m;
    m.baseColorFactor = glm::vec4(albedo, 1.0f);
    return m;
}

Scene baseScene() {
    Scene s;
    s.name = "dvs_test";
    s.sourcePath = "<test>";
    s.materials.push_back(diffuse(glm::vec3(kAlbedo)));
    s.settings.width = 64;
    s.settings.height = 64;
    return s;
}

/** Floor y = 0 over [-0.9, 0.9]^2 facing +y. */
void addFloor(Scene& s) {
    appendQuad(s, {-0.9f, 0, -0.9f}, {0.9f, 0, -0.9f}, {0.9f, 0, 0.9f}, {-0.9f, 0, 0.9f}, {0, 1, 0},
               0);
}

Light pointLight(glm::vec3 p, float intensity) {
    Light l;
    l.type = LightType::Point;
    l.position = p;
    l.intensity = glm::vec3(intensity);
    l.color = l.intensity;
    return l;
}

/** 32^3 grid over [-1, 1] in x, z; y from -0.53125 so y = 0 is the centre of row 8. */
VoxelGrid testGrid() {
    return VoxelGrid::fromCube({-1.0f, -0.53125f, -1.0f}, 2.0f, 32);
}

DvsSettings settingsWith(DvsVoxelShadows shadows, DvsLambert lambert = DvsLambert::Cosine) {
    DvsSettings s;
    s.voxelResolution = 32;
    s.voxelShadows = shadows;
    s.lambert = lambert;
    return s;
}

/** Runs voxelization + L1 on a hand-built scene and returns the base radiance volume. */
class GpuDvsVoxel : public test::ValidatedGpuTest {
protected:
    std::vector<glm::vec4> lightVoxels(Scene scene, const DvsSettings& settings) {
        scene.computeCaps();
        vk::GpuScene gpuScene(*m_ctx, scene);
        SharedPasses shared(*m_ctx, gpuScene, 64, 64);
        m_ctx->submitAndWait([&](VkCommandBuffer cmd) { shared.recordShadows(cmd); });
        Voxelizer voxelizer(*m_ctx, gpuScene, testGrid());
        VoxelRadiance radiance(*m_ctx, testGrid(), {}, "dvs_test/radiance");
        DvsVoxelLighting lighting(*m_ctx, voxelizer, radiance, shared.shadows(), settings,
                                  "dvs_test/lighting");
        m_ctx->submitAndWait([&](VkCommandBuffer cmd) {
            voxelizer.record(cmd);
            lighting.recordDirect(cmd);
            radiance.filter(cmd);
        });
        return radiance.readLevel(0, 0);
    }
    static glm::vec4 at(const std::vector<glm::vec4>& v, glm::ivec3 c) {
        return v[testGrid().linearIndex(c)];
    }
    /** a (rho / pi) I / d^2 cos for a floor voxel (normal +y), position centre + n v / 2. */
    static float floorExpected(glm::ivec3 c, glm::vec3 light, float intensity) {
        const VoxelGrid g = testGrid();
        const glm::vec3 p = g.voxelCenter(c) + glm::vec3(0, 0.5f * g.voxelSize(), 0);
        const glm::vec3 d = light - p;
        const float r2 = glm::dot(d, d);
        const float cosTheta = d.y / std::sqrt(r2);
        return kAlbedo / kPi * intensity / r2 * cosTheta;
    }
};

TEST_F(GpuDvsVoxel, FloorUnderPointLightMatchesLambert) {
    Scene s = baseScene();
    addFloor(s);
    const glm::vec3 light(0.03125f, 0.5f, 0.03125f);
    s.lights.push_back(pointLight(light, 1.0f));
    for (DvsLambert lambert : {DvsLambert::Cosine, DvsLambert::NormalWeighted}) {
        const std::vector<glm::vec4> v =
            lightVoxels(s, settingsWith(DvsVoxelShadows::ShadowMap, lambert));
        for (glm::ivec3 c : {glm::ivec3(16, 8, 16), glm::ivec3(22, 8, 16), glm::ivec3(9, 8, 25)}) {
            const glm::vec4 got = at(v, c);
            const float want = floorExpected(c, light, 1.0f);
            EXPECT_NEAR(got.w, 1.0f, 1e-6f) << c.x << "," << c.z;
            EXPECT_NEAR(got.r, want, 0.01f * want) << c.x << "," << c.z;
            EXPECT_NEAR(got.g, got.r, 1e-6f);
        }
        EXPECT_EQ(at(v, {16, 12, 16}), glm::vec4(0.0f));  // empty voxel
    }
}

TEST_F(GpuDvsVoxel, NormalWeightedLambertOnDiagonalPlane) {
    // Plane x + y = 0 facing N = (1, 1, 0)/sqrt2, directional light with Psi = N, E = 1 W/m^2:
    // cosine gives rho/pi, normal-weighted sum N_w^2 D_w = 0.707 rho/pi (notes 003 §6).
    Scene s = baseScene();
    appendQuad(s, {-0.4f, 0.4f, -0.6f}, {0.4f, -0.4f, -0.6f}, {0.4f, -0.4f, 0.6f},
               {-0.4f, 0.4f, 0.6f}, {1, 1, 0}, 0);
    Light sun;
    sun.type = LightType::Directional;
    sun.direction = -glm::normalize(glm::vec3(1, 1, 0));
    sun.intensity = glm::vec3(1.0f);
    sun.color = sun.intensity;
    s.lights.push_back(sun);
    const float rhoPi = kAlbedo / kPi;
    for (auto [lambert, factor] : {std::pair{DvsLambert::Cosine, 1.0f},
                                   std::pair{DvsLambert::NormalWeighted, 0.70710678f}}) {
        const std::vector<glm::vec4> v =
            lightVoxels(s, settingsWith(DvsVoxelShadows::Raycast, lambert));
        double sum = 0.0;
        size_t count = 0;
        for (const glm::vec4& x : v) {
            if (x.w <= 0.0f) continue;
            ASSERT_TRUE(std::isfinite(x.r));
            sum += x.r;
            ++count;
        }
        ASSERT_GT(count, 100u);
        EXPECT_NEAR(sum / double(count), factor * rhoPi, 0.02 * rhoPi);
    }
}

TEST_F(GpuDvsVoxel, ZeroLengthNormalIsIsotropicNotNaN) {
    // Two opposite faces in the same voxels: the averaged normal vanishes (notes 003 §6).
    Scene s = baseScene();
    appendQuad(s, {0.01f, -0.3f, -0.3f}, {0.01f, 0.3f, -0.3f}, {0.01f, 0.3f, 0.3f},
               {0.01f, -0.3f, 0.3f}, {1, 0, 0}, 0);
    appendQuad(s, {0.01f, -0.3f, -0.3f}, {0.01f, 0.3f, -0.3f}, {0.01f, 0.3f, 0.3f},
               {0.01f, -0.3f, 0.3f}, {-1, 0, 0}, 0);
    Light sun;
    sun.type = LightType::Directional;
    sun.direction = glm::vec3(-1, 0, 0);
    sun.intensity = glm::vec3(2.0f);
    sun.color = sun.intensity;
    s.lights.push_back(sun);
    const std::vector<glm::vec4> v =
        lightVoxels(s, settingsWith(DvsVoxelShadows::Raycast, DvsLambert::NormalWeighted));
    size_t occupied = 0;
    for (const glm::vec4& x : v) {
        ASSERT_TRUE(std::isfinite(x.r) && std::isfinite(x.g) && std::isfinite(x.b));
        if (x.w <= 0.0f) continue;
        ++occupied;
        EXPECT_NEAR(x.r, 0.25f * kAlbedo / kPi * 2.0f, 1e-3f);  // isotropic 1/4
    }
    EXPECT_GT(occupied, 50u);
}

TEST_F(GpuDvsVoxel, VoxelBehindOccluderIsDarkInEveryShadowMode) {
    // A plate at y = 0.25 over [-0.25, 0.25]^2 between the light and the floor's centre.
    Scene s = baseScene();
    addFloor(s);
    appendQuad(s, {-0.25f, 0.25f, -0.25f}, {0.25f, 0.25f, -0.25f}, {0.25f, 0.25f, 0.25f},
               {-0.25f, 0.25f, 0.25f}, {0, 1, 0}, 0);
    const glm::vec3 light(0.03125f, 0.5f, 0.03125f);
    s.lights.push_back(pointLight(light, 1.0f));
    const glm::ivec3 hidden(16, 8, 16), lit(29, 8, 16);
    const float litWant = floorExpected(lit, light, 1.0f);
    for (DvsVoxelShadows mode :
         {DvsVoxelShadows::ShadowMap, DvsVoxelShadows::Raycast, DvsVoxelShadows::RaycastSoft}) {
        const std::vector<glm::vec4> v = lightVoxels(s, settingsWith(mode));
        EXPECT_LT(at(v, hidden).r, 0.02f * floorExpected(hidden, light, 1.0f)) << int(mode);
        EXPECT_NEAR(at(v, lit).r, litWant, 0.02f * litWant) << int(mode);
    }
}

// ---- the technique through the harness -------------------------------------------------------

class GpuDvsRender : public test::ValidatedGpuTest {
protected:
    std::vector<ImageLayer> render(const Scene& scene, ParamSet params) {
        params.set("voxel_resolution", "32");
        FrameHarness harness(*m_ctx, scene, "dvs", params, defaultSharedParams());
        harness.setup();
        harness.renderFrame();
        return harness.readLayers();
    }
    static Scene cornellSpot() {
        Scene s = loadSceneFile(std::string(GILAB_SOURCE_DIR) + "/scenes/cornell_box.json", "spot");
        s.settings.width = 64;
        s.settings.height = 64;
        return s;
    }
    static const Image& layer(const std::vector<ImageLayer>& layers, const std::string& name) {
        for (const ImageLayer& l : layers)
            if (l.name == name) return l.image;
        throw Error("no layer " + name);
    }
};

TEST_F(GpuDvsRender, CornellSpotIndirectIsFiniteWithColourBleeding) {
    const std::vector<ImageLayer> layers =
        render(cornellSpot(), TechniqueRegistry::instance().defaultParams("dvs"));
    const Image& ind = layer(layers, "indirect");
    double left[3] = {0, 0, 0}, right[3] = {0, 0, 0}, total = 0.0;
    for (int y = 0; y < ind.height(); ++y) {
        for (int x = 0; x < ind.width(); ++x) {
            for (int c = 0; c < 3; ++c) {
                const float v = ind.at(x, y, c);
                ASSERT_TRUE(std::isfinite(v));
                ASSERT_GE(v, 0.0f);
                total += v;
                if (x < ind.width() / 3) left[c] += v;
                if (x >= 2 * ind.width() / 3) right[c] += v;
            }
        }
    }
    EXPECT_GT(total, 0.0);
    // Red wall on the left, green on the right: the left third is redder than the right third.
    EXPECT_GT(left[0] / left[1], 1.1 * right[0] / right[1]);
    const Image& ao = layer(layers, "debug_ao");
    for (float v : ao.values())
        ASSERT_TRUE(v >= 0.0f && v <= 1.0f);
}

TEST_F(GpuDvsRender, SecondBounceAddsEnergy) {
    ParamSet params = TechniqueRegistry::instance().defaultParams("dvs");
    params.set("ao_view", "false");
    const Image one = layer(render(cornellSpot(), params), "indirect");
    params.set("bounces", "2");
    EXPECT_EQ(claimedBounces(TechniqueRegistry::instance().get("dvs"), params), 2);
    const Image two = layer(render(cornellSpot(), params), "indirect");
    double sum1 = 0.0, sum2 = 0.0;
    for (size_t i = 0; i < one.values().size(); ++i) {
        const float a = one.values()[i], b = two.values()[i];
        ASSERT_TRUE(std::isfinite(b));
        EXPECT_GE(b, a - 2e-3f * a - 1e-7f) << i;
        sum1 += a;
        sum2 += b;
    }
    EXPECT_GT(sum2, 1.02 * sum1);
}

TEST_F(GpuDvsRender, EmitterLightsVoxelsWithoutGatheringItsEmission) {
    // Built-in Cornell box: the only source is the ceiling emitter. L1 lights the voxels through
    // the emitter samples, so the indirect layer is bounced light: non-zero, and far below the
    // emitter's own radiance on the pixels that see the emitter.
    Scene s = makeBuiltinDefaultScene();
    s.settings.width = 64;
    s.settings.height = 64;
    const std::vector<ImageLayer> layers =
        render(s, TechniqueRegistry::instance().defaultParams("dvs"));
    const Image& ind = layer(layers, "indirect");
    const Image& emission = layer(layers, "emission");
    double total = 0.0;
    size_t emitterPixels = 0;
    for (int y = 0; y < ind.height(); ++y) {
        for (int x = 0; x < ind.width(); ++x) {
            for (int c = 0; c < 3; ++c) {
                ASSERT_TRUE(std::isfinite(ind.at(x, y, c)));
                total += ind.at(x, y, c);
            }
            if (emission.at(x, y, 0) <= 0.0f) continue;
            ++emitterPixels;
            EXPECT_LT(ind.at(x, y, 0), 0.05f * emission.at(x, y, 0));
        }
    }
    EXPECT_GT(total, 0.0);
    EXPECT_GT(emitterPixels, 0u);
}

TEST_F(GpuDvsRender, SpecularConeAddsLightOnGlossySurfaces) {
    Scene s = cornellSpot();
    for (Material& m : s.materials)
        m.roughness = 0.3f;
    s.computeCaps();
    ASSERT_TRUE(s.caps.hasGlossy);
    ParamSet params = TechniqueRegistry::instance().defaultParams("dvs");
    params.set("ao_view", "false");
    params.set("specular", "false");
    const Image off = layer(render(s, params), "indirect");
    params.set("specular", "true");
    const Image on = layer(render(s, params), "indirect");
    double sumOff = 0.0, sumOn = 0.0;
    for (size_t i = 0; i < on.values().size(); ++i) {
        ASSERT_TRUE(std::isfinite(on.values()[i]));
        EXPECT_GE(on.values()[i], off.values()[i] - 1e-6f);
        sumOff += off.values()[i];
        sumOn += on.values()[i];
    }
    EXPECT_GT(sumOn, 1.01 * sumOff);
}

TEST_F(GpuDvsRender, ConeShadowsAndSourceCombineStayFinite) {
    ParamSet params = TechniqueRegistry::instance().defaultParams("dvs");
    params.set("pixel_shadows", "cone");
    params.set("combine", "source");
    const std::vector<ImageLayer> layers = render(cornellSpot(), params);
    const Image& direct = layer(layers, "direct");
    double sum = 0.0;
    for (float v : direct.values()) {
        ASSERT_TRUE(std::isfinite(v));
        ASSERT_GE(v, 0.0f);
        sum += v;
    }
    EXPECT_GT(sum, 0.0);
}

// ---- parameters -------------------------------------------------------------------------------

TEST(CpuDvsParams, ErrorsNameTheKey) {
    ParamSet p = TechniqueRegistry::instance().defaultParams("dvs");
    auto expectKey = [&](const std::string& key, const std::string& value) {
        try {
            ParamSet q = p;
            q.set(key, value);
            dvsSettingsFrom(q);
            ADD_FAILURE() << key << "=" << value << " accepted";
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
        }
    };
    expectKey("bounces", "3");
    expectKey("voxel_shadows", "ray");
    expectKey("voxel_resolution", "96");  // not a power of two
    expectKey("specular_aperture_deg", "0.5");
    expectKey("step_factor", "0");
    const DvsSettings s = dvsSettingsFrom(p);
    EXPECT_EQ(s.diffuseCones, 6u);
    EXPECT_EQ(s.bounces, 1);
    EXPECT_EQ(TechniqueRegistry::instance().get("dvs").bouncesParam, "bounces");
}

TEST(CpuDvsParams, SpecularApertureFromRoughness) {
    EXPECT_FLOAT_EQ(dvsSpecularApertureDeg(0.0f), 1.0f);   // clamped below
    EXPECT_FLOAT_EQ(dvsSpecularApertureDeg(1.0f), 60.0f);  // clamped above
    float prev = 0.0f;
    for (float r = 0.05f; r <= 1.0f; r += 0.05f) {
        const float a = dvsSpecularApertureDeg(r);
        EXPECT_GE(a, prev);
        prev = a;
    }
    // roughness 0.3: alpha 0.09, n = 244.9, full angle 2 acos(0.5^(1/n)) = 8.617 deg.
    EXPECT_NEAR(dvsSpecularApertureDeg(0.3f), 8.617f, 0.02f);
    EXPECT_NEAR(dvsBounceApertureDeg(), 53.13f, 0.01f);
}

}  // namespace
}  // namespace gilab
