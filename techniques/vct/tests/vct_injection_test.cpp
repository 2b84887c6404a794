// `vct` light injection (techniques/vct/README.md, "Light injection"): per-photon irradiance
// averaged per voxel and light is exact for planes at any orientation; emitter samples are injected
// through hemicube light-view maps carrying the area light's flux; auto map sizes follow the
// footprint rule and stay inside the storage-buffer limit. Small grids (32^3, 64^3), 64^2 images.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "techniques/vct/tests/vct_test_rig.h"
#include "tests/gpu_test_fixture.h"
#include "tests/indirect_energy.h"

#include "core/gpu/gpu_scene.h"
#include "core/image/image.h"
#include "core/passes/emitter_samples.h"
#include "core/passes/shared_passes.h"
#include "core/scene/mesh_builder.h"
#include "core/scene/scene_loader.h"
#include "core/technique/frame_harness.h"
#include "core/technique/registry.h"
#include "core/util/error.h"
#include "core/voxel/voxel_radiance.h"
#include "reference/path_tracer.h"
#include "techniques/vct/light_injection.h"
#include "techniques/vct/vct.h"

namespace gilab {
namespace {

constexpr double kPi = 3.14159265358979323846;
const glm::vec3 kAlbedo(0.6f, 0.5f, 0.4f);

using test::cornell;
using test::vctParams;
using test::VctRig;

/** The plane of the test: a square of side `size` centred at the origin, its normal tilted by
 *  `tiltDeg` from +y about the z axis (0: horizontal; 45: at 45 degrees to two voxel axes). */
struct Plane {
    float size = 2.0f;
    glm::vec3 n{0.0f, 1.0f, 0.0f}, u{1.0f, 0.0f, 0.0f}, w{0.0f, 0.0f, 1.0f};
    explicit Plane(float tiltDeg) {
        const float t = glm::radians(tiltDeg);
        n = glm::vec3(-std::sin(t), std::cos(t), 0.0f);
        u = glm::vec3(std::cos(t), std::sin(t), 0.0f);
    }
};

Scene planeScene(const Plane& plane, const Light& light) {
    Scene s;
    s.name = "vct_injection_plane";
    s.sourcePath = "<test>";
    Material m;
    m.baseColorFactor = glm::vec4(kAlbedo, 1.0f);
    s.materials.push_back(m);
    const float h = 0.5f * plane.size;
    appendQuad(s, -h * plane.u - h * plane.w, h * plane.u - h * plane.w, h * plane.u + h * plane.w,
               -h * plane.u + h * plane.w, plane.n, 0);
    // A small quad below the plane moves the scene bounds, so that the grid (centred on them)
    // does not put the plane on voxel faces
    const glm::vec3 c(h * std::abs(plane.u.x) + 0.1f, -h * std::abs(plane.u.y) - 0.15f, 0.05f);
    const float q = 0.02f;
    appendQuad(s, c - q * plane.u - q * plane.w, c + q * plane.u - q * plane.w,
               c + q * plane.u + q * plane.w, c - q * plane.u + q * plane.w, plane.n, 0);
    s.lights.push_back(light);
    s.camera.position = 3.0f * plane.n;
    s.camera.target = glm::vec3(0.0f);
    s.camera.up = plane.u;
    s.settings.width = 16;
    s.settings.height = 16;
    s.computeCaps();
    return s;
}

struct Agreement {
    size_t voxels = 0;
    double meanRatio = 0.0;    // injected / analytic, averaged over the voxels
    double maxRelError = 0.0;  // over voxels and channels
    double fluxRatio = 0.0;    // sum(flux) / v0^2 / analytic: the old normalisation
};

/**
 * Compares the injected irradiance and the radiance base of every covered voxel whose centre
 * projects onto the plane's interior (2 voxels from its edges) with E(x) = intensity x
 * geometry(x) at that projection: radiance = a albedo / pi E with a = 1.
 */
Agreement compare(VctRig& rig, const Plane& plane, const glm::vec3& intensity,
                  const std::function<double(glm::vec3)>& geometry) {
    const VoxelGrid& grid = rig.technique.grid();
    const float v0 = grid.voxelSize();
    const std::vector<glm::vec3> irradiance = rig.technique.injection()->readVoxelIrradiance();
    const std::vector<glm::vec3> flux = rig.technique.injection()->readVoxelFlux();
    const std::vector<glm::vec4> base = rig.technique.radiance()->readLevel(0, 0);
    Agreement a;
    double sumRatio = 0.0, sumFlux = 0.0;
    const int n = int(grid.resolution());
    for (int z = 0; z < n; ++z) {
        for (int y = 0; y < n; ++y) {
            for (int x = 0; x < n; ++x) {
                const size_t i = grid.linearIndex({x, y, z});
                if (base[i].a <= 0.0f) continue;
                const glm::vec3 c = grid.voxelCenter({x, y, z});
                if (std::abs(glm::dot(plane.n, c)) > 2.0f * v0) continue;  // the small quad
                const glm::vec3 p = c - plane.n * glm::dot(plane.n, c);
                const float limit = 0.5f * plane.size - 2.0f * v0;
                if (std::abs(glm::dot(p, plane.u)) > limit ||
                    std::abs(glm::dot(p, plane.w)) > limit)
                    continue;
                const double g = geometry(p), e = double(intensity.x) * g;
                for (int k = 0; k < 3; ++k) {
                    const double ek = double(intensity[k]) * g;
                    const double fromIrradiance = double(irradiance[i][k]) / ek;
                    const double fromRadiance = double(base[i][k]) * kPi / (kAlbedo[k] * ek);
                    a.maxRelError = std::max({a.maxRelError, std::abs(fromIrradiance - 1.0),
                                              std::abs(fromRadiance - 1.0)});
                }
                sumRatio += double(irradiance[i].x) / e;
                sumFlux += double(flux[i].x) / (double(v0) * v0) / e;
                ++a.voxels;
            }
        }
    }
    if (a.voxels > 0) {
        a.meanRatio = sumRatio / double(a.voxels);
        a.fluxRatio = sumFlux / double(a.voxels);
    }
    return a;
}

using GpuVctInjection = test::ValidatedGpuTest;

}  // namespace

// A directional light on a plane at 0, 30 and 45 degrees to a voxel axis: every voxel holds
// E_perp cos(theta) (the binary-coverage normalisation sum(flux) / v0^2 gives the mean plane area
// per covered voxel instead: 1 / (|nx| + |ny| + |nz|)).
TEST_F(GpuVctInjection, PlaneUnderDirectionalLightIsExactAtAnyTilt) {
    for (float tilt : {0.0f, 30.0f, 45.0f}) {
        const Plane plane(tilt);
        Light light;
        light.type = LightType::Directional;
        light.direction = glm::normalize(glm::vec3(0.2f, -1.0f, 0.3f));
        light.intensity = glm::vec3(2.0f, 1.0f, 0.5f);
        light.color = light.intensity;
        VctRig rig(*m_ctx, planeScene(plane, light), vctParams({}));
        const double cosTheta = -glm::dot(plane.n, light.direction);
        const Agreement a =
            compare(rig, plane, light.intensity, [&](glm::vec3) { return cosTheta; });
        std::printf(
            "directional, tilt %2.0f deg: %zu voxels, injected/analytic mean %.5f, max "
            "rel error %.2e; sum(flux)/v0^2 would give %.4f (1/sum|n| = %.4f)\n",
            tilt, a.voxels, a.meanRatio, a.maxRelError, a.fluxRatio,
            1.0 / (std::abs(plane.n.x) + std::abs(plane.n.y) + std::abs(plane.n.z)));
        ASSERT_GT(a.voxels, 200u);
        EXPECT_NEAR(a.meanRatio, 1.0, 0.002) << "tilt " << tilt;
        EXPECT_LT(a.maxRelError, 0.01) << "tilt " << tilt;
    }
}

// A point light 1.5 m from the plane's centre along its normal: every voxel holds I cos / r^2 of
// the voxel centre's projection onto the plane (within the variation of E over a voxel).
TEST_F(GpuVctInjection, PlaneUnderPointLightMatchesInverseSquare) {
    for (float tilt : {0.0f, 30.0f, 45.0f}) {
        const Plane plane(tilt);
        Light light;
        light.type = LightType::Point;
        light.position = 1.5f * plane.n;
        light.intensity = glm::vec3(3.0f, 2.0f, 1.0f);
        light.color = light.intensity;
        VctRig rig(*m_ctx, planeScene(plane, light), vctParams({}));
        const Agreement a = compare(rig, plane, light.intensity, [&](glm::vec3 p) {
            const glm::dvec3 d = glm::dvec3(light.position) - glm::dvec3(p);
            const double r = glm::length(d);
            return glm::dot(glm::dvec3(plane.n), d) / (r * r * r);
        });
        std::printf(
            "point, tilt %2.0f deg: %zu voxels, injected/analytic mean %.5f, max rel "
            "error %.2e; sum(flux)/v0^2 would give %.4f; maps %s\n",
            tilt, a.voxels, a.meanRatio, a.maxRelError, a.fluxRatio,
            rig.technique.injection()->mapSummary().c_str());
        ASSERT_GT(a.voxels, 200u);
        EXPECT_NEAR(a.meanRatio, 1.0, 0.005) << "tilt " << tilt;
        EXPECT_LT(a.maxRelError, 0.03) << "tilt " << tilt;
    }
}

// The hemicube views of an emitter sample cover its hemisphere exactly (a double-sided sample's
// cube the whole sphere): the window solid angles sum to 2 pi (4 pi).
TEST(CpuVctInjection, EmitterHemicubesCoverTheLobe) {
    const Scene scene = cornell("");
    const VoxelGrid grid(scene.caps.bounds, 32);
    for (bool twoSided : {false, true}) {
        EmitterSample s;
        s.position = glm::vec3(0.3f, 0.5f, 0.25f);
        s.normal = glm::normalize(glm::vec3(0.1f, -1.0f, 0.2f));
        s.intensity = glm::vec3(1.0f);
        s.twoSided = twoSided;
        const auto views = vct::buildLightViews(scene, grid, {s});
        const size_t punctual = scene.lights.size() == 0 ? 0 : views.size() - (twoSided ? 6 : 5);
        ASSERT_EQ(views.size() - punctual, twoSided ? 6u : 5u);
        double omega = 0.0;
        for (size_t i = punctual; i < views.size(); ++i)
            omega += vct::lightViewFluxBound(views[i]).x;
        EXPECT_NEAR(omega, (twoSided ? 4.0 : 2.0) * kPi, 1e-6);  // float axes
    }
}

// Auto map sizes: a texel's footprint on the farthest grid corner in front of each view is at
// most v0 / 2 (directional: side / texels <= v0 / 2); a small photon budget shrinks the maps
// (noted) and packs whole lights into batches that fit it.
TEST(CpuVctInjection, AutoMapSizesFollowTheFootprintRuleAndTheBudget) {
    for (const char* variant : {"spot", "point", ""}) {
        Scene scene = cornell(variant);
        Light sun;
        sun.type = LightType::Directional;
        sun.direction = glm::normalize(glm::vec3(0.3f, -1.0f, 0.1f));
        sun.intensity = glm::vec3(1.0f);
        sun.color = sun.intensity;
        scene.lights.push_back(sun);
        const VoxelGrid grid(scene.caps.bounds, 64);
        const auto samples = buildEmitterSamples(scene, 16);
        const auto views = vct::buildLightViews(scene, grid, samples);
        vct::LightViewLimits limits;
        const vct::LightViewPlan plan = vct::planLightViews(views, grid, 0, limits);
        EXPECT_TRUE(plan.notes.empty()) << plan.notes.front();
        const float v0 = grid.voxelSize();
        double worst = 0.0;
        for (const vct::GpuLightView& v : plan.views) {
            const double tx = 2.0 * v.axisX.w / v.texels.x, ty = 2.0 * v.axisY.w / v.texels.y;
            double footprint = std::max(tx, ty);
            if (v.positionKind.w < 0.5f) {
                double far = 0.0;
                for (int k = 0; k < 8; ++k) {
                    const glm::vec3 c =
                        grid.origin() + grid.side() * glm::vec3(k & 1, (k >> 1) & 1, (k >> 2) & 1);
                    const glm::vec3 m =
                        glm::normalize(glm::cross(glm::vec3(v.axisX), glm::vec3(v.axisY)));
                    const float facing = glm::dot(m, glm::vec3(v.forward)) > 0.0f ? 1.0f : -1.0f;
                    if (facing * glm::dot(m, c - glm::vec3(v.positionKind)) > 0.0f)
                        far = std::max(far, double(glm::length(c - glm::vec3(v.positionKind))));
                }
                footprint *= far;
            }
            worst = std::max(worst, footprint / v0);
            EXPECT_LE(footprint, 0.5 * v0 * (1.0 + 1e-5));
        }
        // Batches of whole lights, <= 32 MiB of photons unless one light alone needs more
        uint64_t largest = 0;
        for (size_t i = 0; i < plan.views.size(); i += plan.views[i].group.z) {
            uint64_t n = 0;
            for (size_t j = i; j < i + plan.views[i].group.z; ++j)
                n += uint64_t(plan.views[j].texels.x) * plan.views[j].texels.y;
            largest = std::max(largest, n);
        }
        for (const vct::LightViewBatch& b : plan.batches) {
            EXPECT_LE(b.photons,
                      std::max<uint64_t>(largest, limits.batchBytes / sizeof(vct::GpuPhoton)));
            EXPECT_EQ(plan.views[b.firstView].group.y, b.firstView);
        }
        if (std::string(variant).empty()) EXPECT_GT(plan.batches.size(), 1u);
        std::printf(
            "cornell#%s + sun at 64^3: %zu views, %llu photons (%.1f MiB), largest "
            "footprint %.3f v0\n",
            variant, plan.views.size(), (unsigned long long)plan.photonCount,
            double(plan.photonCount * sizeof(vct::GpuPhoton)) / 1048576.0, worst);

        // A budget of 40000 photons: lights above it shrink, the rest go in batches of whole lights
        limits.photonBufferBytes = 40000 * sizeof(vct::GpuPhoton);
        const vct::LightViewPlan small = vct::planLightViews(views, grid, 0, limits);
        EXPECT_FALSE(small.notes.empty());
        uint64_t total = 0;
        for (const vct::LightViewBatch& b : small.batches) {
            EXPECT_LE(b.photons, 40000u);
            total += b.photons;
            const vct::GpuLightView& first = small.views[b.firstView];
            EXPECT_EQ(first.group.y, b.firstView);  // starts with a whole light
        }
        EXPECT_EQ(total, small.photonCount);
        limits.singleBatch = true;
        const vct::LightViewPlan one = vct::planLightViews(views, grid, 0, limits);
        EXPECT_EQ(one.batches.size(), 1u);
        EXPECT_LE(one.photonCount, 40000u);
    }
}

// The area-lit Cornell box (the built-in default): the photons of the emitter samples' hemicubes
// carry the emitters' whole flux, pi Le A (Lambertian, one-sided), to within the quadrature error.
TEST_F(GpuVctInjection, EmitterPhotonsCarryTheAreaLightsFlux) {
    VctRig rig(*m_ctx, cornell(""), vctParams({{"light_map_resolution", "64"}}));
    const auto& inj = *rig.technique.injection();
    ASSERT_EQ(inj.batchCount(), 1u);
    const uint32_t samples = uint32_t(rig.shared.shadows().emitterSamples().size());
    ASSERT_GT(samples, 0u);
    EXPECT_EQ(inj.lightCount(), samples);
    EXPECT_EQ(inj.photonCount(), uint64_t(samples) * (64 * 64 + 4 * 64 * 32));
    glm::dvec3 analytic(0.0);
    const Scene& s = rig.scene;
    for (size_t t = 0; t < s.triangleCount(); ++t) {
        const Material& m = s.materials[s.triangleMaterials[t]];
        if (!m.isEmissive()) continue;
        const glm::vec3 p0 = s.vertices[s.indices[3 * t]].position;
        const glm::vec3 p1 = s.vertices[s.indices[3 * t + 1]].position;
        const glm::vec3 p2 = s.vertices[s.indices[3 * t + 2]].position;
        const double area = 0.5 * glm::length(glm::cross(p1 - p0, p2 - p0));
        analytic += kPi * glm::dvec3(m.emissiveFactor) * area * (m.doubleSided ? 2.0 : 1.0);
    }
    glm::dvec3 photons(0.0), hit(0.0);
    for (const vct::GpuPhoton& p : rig.technique.injection()->readPhotons()) {
        photons += glm::dvec3(p.flux);
        if (p.positionValid.w > 0.5f) hit += glm::dvec3(p.flux);
    }
    for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(photons[c], analytic[c], 0.01 * analytic[c]) << "channel " << c;
    std::printf(
        "emitter photons: flux %.5f W vs pi Le A = %.5f W (red), %.1f %% of it hits the "
        "box\n",
        photons.x, analytic.x, 100.0 * hit.x / photons.x);
    // The box is closed but for its front: from the ceiling light the open side takes about a
    // fifth of the cosine-weighted hemisphere (like each of the four side walls)
    EXPECT_GT(hit.x, 0.75 * photons.x);
    EXPECT_LT(hit.x, 0.9 * photons.x);
}

// vct runs on the area-lit Cornell box with the auto map sizes: finite, non-negative, and its
// indirect layer carries about the path tracer's one-bounce energy.
TEST_F(GpuVctInjection, AreaLitCornellIndirectIsFiniteAndNearTheReference) {
    const Scene scene = cornell("", 64);
    ParamSet params = vctParams({{"voxel_resolution", "64"}});
    FrameHarness h(*m_ctx, scene, "vct", params, defaultSharedParams());
    ASSERT_TRUE(h.support().supported) << h.support().reason;
    const SetupTiming setup = h.setup();
    h.renderFrame();
    const auto layers = h.readLayers();
    for (const std::string& note : h.notes())
        std::printf("note: %s\n", note.c_str());
    for (const auto& p : setup.passes)
        if (p.name.rfind("vct/inject", 0) == 0)
            std::printf("%s %.1f ms\n", p.name.c_str(), p.gpuMs);
    const double vct = test::indirectLayerSum(layers);
    ASSERT_GE(vct, 0.0);
    const double reference = test::oneBounceReferenceSum(scene, 64);
    ASSERT_GT(reference, 0.0);
    std::printf("area-lit Cornell, 64^2, N = 64: indirect energy vct / reference = %.3f\n",
                vct / reference);
    EXPECT_GT(vct / reference, 0.5);
    EXPECT_LT(vct / reference, 1.5);
}

}  // namespace gilab
