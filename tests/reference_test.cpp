// The reference path tracer against closed forms: furnaces (every bounce layer), punctual
// lights, an area light under every estimator, alpha masks, the BSDF's sampling, determinism
// and the non-finite guard. Tolerances are derived from the measured standard errors:
// |mean - expected| < k sigma + a small relative term for float rounding.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include "core/image/color.h"
#include "core/scene/mesh_builder.h"
#include "core/scene/procedural_cornell.h"
#include "core/scene/scene_loader.h"
#include "core/util/error.h"
#include "reference/bsdf.h"
#include "reference/integrator.h"
#include "reference/light_power.h"
#include "reference/lights.h"
#include "reference/path_tracer.h"
#include "reference/sampling.h"
#include "reference/texture_lookup.h"

namespace gilab::ref {
namespace {

constexpr double kPiD = 3.14159265358979323846;

// ---------------------------------------------------------------------------------------------
// Scenes, rendering and statistics
// ---------------------------------------------------------------------------------------------

Material lambert(glm::vec3 albedo, glm::vec3 emission = glm::vec3(0.0f)) {
    Material m;
    m.baseColorFactor = glm::vec4(albedo, 1.0f);
    m.emissiveFactor = emission;
    return m;
}

Scene emptyScene(const std::string& name, int size) {
    Scene s;
    s.name = name;
    s.sourcePath = "<test>";
    s.settings.width = size;
    s.settings.height = size;
    return s;
}

uint32_t addMaterial(Scene& s, const Material& m) {
    s.materials.push_back(m);
    return uint32_t(s.materials.size() - 1);
}

/** Horizontal square [-half, half]^2 at height y facing +y or -y (u along +x if facing -y). */
void addHorizontalQuad(Scene& s, float y, float half, float facingY, uint32_t m,
                       glm::vec2 centre = glm::vec2(0.0f)) {
    const float x0 = centre.x - half, x1 = centre.x + half;
    const float z0 = centre.y - half, z1 = centre.y + half;
    appendQuad(s, {x0, y, z0}, {x1, y, z0}, {x1, y, z1}, {x0, y, z1}, {0.0f, facingY, 0.0f}, m);
}

Camera lookDown(glm::vec3 eye, float vfovDeg) {
    Camera c;
    c.position = eye;
    c.target = eye - glm::vec3(0.0f, 1.0f, 0.0f);
    c.up = {0.0f, 0.0f, -1.0f};
    c.vfovRad = glm::radians(vfovDeg);
    return c;
}

Light pointLight(glm::vec3 p, glm::vec3 intensity) {
    Light l;
    l.type = LightType::Point;
    l.position = p;
    l.intensity = intensity;
    l.color = l.intensity;
    return l;
}

ReferenceSettings settingsWith(Estimator e, int maxBounces, uint64_t seed = 7) {
    ReferenceSettings s;
    s.estimator = e;
    s.maxBounces = maxBounces;
    s.seed = seed;
    s.pixelFilter = PixelFilter::Box;  // the expectations below average over each pixel
    return s;
}

Accumulator render(Scene scene, const ReferenceSettings& settings, uint32_t spp,
                   RayStats* stats = nullptr) {
    scene.computeCaps();
    PathTracer tracer(scene, settings);
    Accumulator acc;
    acc.reset(scene.settings.width, scene.settings.height);
    EXPECT_TRUE(tracer.addSamples(acc, spp));
    if (stats) *stats = tracer.stats();
    return acc;
}

struct Estimate {
    double mean = 0.0;
    double sigma = 0.0;  // standard error of `mean`
};

/** Mean of a layer over all pixels and channels weighted by w, with its standard error
 *  (pixels are independent, so the variances add). */
Estimate imageMean(const Accumulator& acc, Layer layer, int channel) {
    Estimate e;
    double var = 0.0;
    const double n = double(acc.width) * double(acc.height);
    for (int y = 0; y < acc.height; ++y)
        for (int x = 0; x < acc.width; ++x) {
            e.mean += acc.mean(layer, x, y, channel);
            const double se = acc.stdError(layer, x, y, channel);
            var += se * se;
        }
    e.mean /= n;
    e.sigma = std::sqrt(var) / n;
    return e;
}

::testing::AssertionResult agrees(const Estimate& e, double expected, double k = 4.0,
                                  double rel = 1e-5) {
    const double tol = k * e.sigma + rel * std::abs(expected) + 1e-9;
    if (std::abs(e.mean - expected) <= tol) return ::testing::AssertionSuccess();
    return ::testing::AssertionFailure()
           << "mean " << e.mean << " +- " << e.sigma << " vs expected " << expected << " (off by "
           << (e.mean - expected) / std::max(e.sigma, 1e-300) << " sigma)";
}

/** Where the camera ray through image point (px, py) meets the plane y = planeY. */
glm::dvec3 planePoint(const Camera& cam, double px, double py, int w, int h, double planeY) {
    const Ray r = cam.primaryRay(float(px), float(py), w, h);
    const glm::dvec3 o(r.origin), d(r.direction);
    const double t = (planeY - o.y) / d.y;
    return o + t * d;
}

/** The box-filtered pixel value of fn(point on the plane): n x n midpoint rule. */
template <class F>
double pixelAverage(const Camera& cam, int x, int y, int w, int h, int n, F fn) {
    double sum = 0.0;
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i)
            sum += fn(planePoint(cam, x + (i + 0.5) / n, y + (j + 0.5) / n, w, h, 0.0));
    return sum / (double(n) * n);
}

/** Differential area to a parallel rectangle with a corner above it, sides a, b at height c
 *  (Howell, "A Catalog of Radiation Heat Transfer Configuration Factors", B-3). */
double formFactorCorner(double a, double b, double c) {
    const double X = a / c, Y = b / c;
    const double sx = std::sqrt(1.0 + X * X), sy = std::sqrt(1.0 + Y * Y);
    return (X / sx * std::atan(Y / sx) + Y / sy * std::atan(X / sy)) / (2.0 * kPiD);
}

/** Form factor from a point (px, pz) on y = 0 (normal +y) to the rectangle [x0,x1]x[z0,z1]
 *  at height c facing down: signed corner rectangles (inclusion-exclusion). */
double formFactorRect(double px, double pz, double x0, double x1, double z0, double z1, double c) {
    auto g = [&](double x, double z) {
        const double s = (x < 0 ? -1.0 : 1.0) * (z < 0 ? -1.0 : 1.0);
        return s * formFactorCorner(std::abs(x), std::abs(z), c);
    };
    return g(x1 - px, z1 - pz) - g(x0 - px, z1 - pz) - g(x1 - px, z0 - pz) + g(x0 - px, z0 - pz);
}

void printMeasured(const char* what, double mean, double sigma, double expected) {
    std::printf("[ measured ] %-40s mean %.6g +- %.2g, expected %.6g, rel diff %+.2e\n", what, mean,
                sigma, expected, expected != 0.0 ? mean / expected - 1.0 : mean);
}

// ---------------------------------------------------------------------------------------------
// Furnaces: every surface emits Le and reflects rho; each layer is a term of the geometric sum
// ---------------------------------------------------------------------------------------------

Scene furnaceScene(float rho, float le) {
    Scene s = emptyScene("furnace", 12);
    const uint32_t m = addMaterial(s, lambert(glm::vec3(rho), glm::vec3(le)));
    for (int axis = 0; axis < 3; ++axis)
        for (float side : {-1.0f, 1.0f}) {
            // Wall at coordinate `side` of `axis`, facing into the cube
            glm::vec3 c[4];
            const int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
            const float corners[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
            for (int i = 0; i < 4; ++i) {
                c[i][axis] = side;
                c[i][a1] = corners[i][0];
                c[i][a2] = corners[i][1];
            }
            glm::vec3 facing(0.0f);
            facing[axis] = -side;
            appendQuad(s, c[0], c[1], c[2], c[3], facing, m);
        }
    s.camera.position = {0.0f, 0.0f, 0.0f};
    s.camera.target = {1.0f, 0.1f, -0.05f};
    s.camera.up = {0.0f, 1.0f, 0.0f};
    s.camera.vfovRad = glm::radians(50.0f);
    return s;
}

/** Expected layer values of the furnace (per unit Le): rho^k for light arriving at vertex k. */
std::vector<double> furnaceExpected(double rho, int maxBounces) {
    std::vector<double> e(kLayerCount, 0.0);
    e[int(Layer::Emission)] = 1.0;
    for (int k = 1; k <= maxBounces + 1; ++k)
        e[int(layerForVertex(k))] += std::pow(rho, k);
    for (int l = 1; l < kLayerCount; ++l)
        e[int(Layer::Full)] += e[l];
    return e;
}

void checkFurnace(float rho, Estimator estimator, int maxBounces, uint32_t spp,
                  int rouletteStart = -1, SamplerKind sampler = SamplerKind::Independent) {
    const float le = 0.75f;
    ReferenceSettings st = settingsWith(estimator, maxBounces);
    st.rouletteStartBounce = rouletteStart;
    st.sampler = sampler;
    const Accumulator acc = render(furnaceScene(rho, le), st, spp);
    const std::vector<double> expected = furnaceExpected(rho, maxBounces);
    for (int l = 0; l < kLayerCount; ++l) {
        const Estimate e = imageMean(acc, Layer(l), 1);
        const double want = le * expected[size_t(l)];
        EXPECT_TRUE(agrees(e, want))
            << "rho " << rho << " " << estimatorName(estimator) << " layer " << layerName(Layer(l));
        char what[96];
        std::snprintf(what, sizeof what, "furnace rho %.1f %s B=%d rr=%d %s", rho,
                      estimatorName(estimator), maxBounces, rouletteStart, layerName(Layer(l)));
        printMeasured(what, e.mean, e.sigma, want);
    }
    EXPECT_EQ(acc.nonFiniteSamples, 0u);
}

TEST(CpuReferenceFurnace, EveryLayerUnderEveryEstimator) {
    for (float rho : {0.5f, 0.8f})
        for (Estimator e : {Estimator::Mis, Estimator::NeeOnly, Estimator::BsdfOnly})
            checkFurnace(rho, e, 6, 1024);
}

TEST(CpuReferenceFurnace, ConvergesToLeOverOneMinusRho) {
    // rho^(B+2) = 0.5^42: the truncated sum equals Le / (1 - rho) to 2e-13
    const float rho = 0.5f, le = 0.75f;
    const Accumulator acc = render(furnaceScene(rho, le), settingsWith(Estimator::Mis, 40), 512);
    const Estimate e = imageMean(acc, Layer::Full, 0);
    EXPECT_TRUE(agrees(e, le / (1.0 - rho)));
    printMeasured("furnace rho 0.5 full, B=40", e.mean, e.sigma, le / (1.0 - rho));
}

TEST(CpuReferenceFurnace, RussianRouletteIsUnbiased) {
    checkFurnace(0.8f, Estimator::Mis, 12, 2048, 1);
}

TEST(CpuReferenceFurnace, DefaultRouletteIsUnbiasedOverManyBounces) {
    // rho = 0.9: the throughput falls below the default threshold (0.2) after ~16 bounces, so
    // the roulette thins the tail of 64 bounces; every layer must still match rho^k.
    const ReferenceSettings defaults;
    checkFurnace(0.9f, Estimator::Mis, 64, 1024, defaults.rouletteStartBounce);
}

TEST(CpuReferenceFurnace, SobolSamplerIsUnbiased) {
    checkFurnace(0.8f, Estimator::Mis, 12, 1024, 4, SamplerKind::Sobol);
    checkFurnace(0.5f, Estimator::NeeOnly, 6, 512, -1, SamplerKind::Sobol);
}

TEST(CpuReferenceFurnace, LayersBeyondMaxBouncesAreZero) {
    const Accumulator acc = render(furnaceScene(0.8f, 1.0f), settingsWith(Estimator::Mis, 1), 4);
    for (Layer l : {Layer::Bounce2, Layer::Bounce3Plus})
        for (double v : std::vector<double>(
                 acc.sum.begin() + acc.index(l, 0, 0, 0),
                 acc.sum.begin() + acc.index(l, 0, 0, 0) + size_t(acc.width * acc.height * 3)))
            ASSERT_EQ(v, 0.0) << layerName(l);
}

// ---------------------------------------------------------------------------------------------
// Punctual lights over a diffuse plane: direct = rho / pi x E, box-filtered over each pixel
// ---------------------------------------------------------------------------------------------

constexpr float kRho = 0.5f;

Scene planeScene(int size, const Camera& camera) {
    Scene s = emptyScene("plane", size);
    addHorizontalQuad(s, 0.0f, 20.0f, 1.0f, addMaterial(s, lambert(glm::vec3(kRho))));
    s.camera = camera;
    return s;
}

/**
 * Checks the direct layer pixel by pixel (5 sigma + 1e-4 of the image mean: a pixel that a
 * light's edge barely touches has too few non-zero samples for its sigma to be reliable) and
 * over the image (4 sigma).
 */
void checkDirectAgainst(const Accumulator& acc, const Camera& cam, int channel,
                        const std::function<double(const glm::dvec3&)>& radiance, const char* what,
                        int quadrature = 16) {
    const int w = acc.width, h = acc.height;
    std::vector<double> expected(size_t(w) * size_t(h));
    double expectedTotal = 0.0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            expected[size_t(y * w + x)] = pixelAverage(cam, x, y, w, h, quadrature, radiance);
            expectedTotal += expected[size_t(y * w + x)];
        }
    const double floor = 1e-4 * expectedTotal / (double(w) * h);
    Estimate total;
    double var = 0.0, maxSigmas = 0.0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const double want = expected[size_t(y * w + x)];
            const double got = acc.mean(Layer::Direct, x, y, channel);
            const double se = acc.stdError(Layer::Direct, x, y, channel);
            EXPECT_LE(std::abs(got - want), 5.0 * se + 1e-4 * want + floor)
                << what << " pixel " << x << "," << y << ": " << got << " +- " << se << " vs "
                << want;
            if (se > floor) maxSigmas = std::max(maxSigmas, std::abs(got - want) / se);
            total.mean += got;
            var += se * se;
        }
    const double n = double(w) * h;
    total.mean /= n;
    total.sigma = std::sqrt(var) / n;
    expectedTotal /= n;
    EXPECT_TRUE(agrees(total, expectedTotal, 4.0, 1e-4)) << what;
    printMeasured(what, total.mean, total.sigma, expectedTotal);
    std::printf("[ measured ] %-40s max |diff| / stderr over pixels: %.2f\n", what, maxSigmas);
}

TEST(CpuReferencePunctual, PointLightOverDiffusePlane) {
    const Camera cam = lookDown({0.0f, 2.0f, 0.0f}, 60.0f);
    Scene s = planeScene(24, cam);
    const glm::dvec3 lp(0.3, 1.0, -0.2);
    const glm::vec3 intensity(2.0f, 1.0f, 0.5f);
    s.lights.push_back(pointLight(glm::vec3(lp), intensity));
    for (Estimator e : {Estimator::Mis, Estimator::BsdfOnly}) {
        const Accumulator acc = render(s, settingsWith(e, 0), 256);
        for (int c = 0; c < 3; ++c) {
            auto radiance = [&](const glm::dvec3& p) {
                const glm::dvec3 d = lp - p;
                const double r2 = glm::dot(d, d);
                return kRho / kPiD * intensity[c] * (d.y / std::sqrt(r2)) / r2;  // I cos / r^2
            };
            checkDirectAgainst(acc, cam, c, radiance, "point light direct");
        }
    }
}

TEST(CpuReferencePunctual, SpotLightInnerFalloffAndOutside) {
    const Camera cam = lookDown({0.0f, 2.0f, 0.0f}, 60.0f);
    Scene s = planeScene(32, cam);
    Light spot;
    spot.type = LightType::Spot;
    spot.position = {0.1f, 1.5f, 0.05f};
    spot.direction = glm::normalize(glm::vec3(0.1f, -1.0f, 0.0f));
    spot.intensity = glm::vec3(3.0f);
    spot.color = spot.intensity;
    spot.innerConeRad = glm::radians(15.0f);
    spot.outerConeRad = glm::radians(30.0f);
    s.lights.push_back(spot);
    const Accumulator acc = render(s, settingsWith(Estimator::Mis, 0), 256);
    const double cosIn = std::cos(double(spot.innerConeRad));
    const double cosOut = std::cos(double(spot.outerConeRad));
    const glm::dvec3 lp(spot.position), axis(spot.direction);
    auto cdAt = [&](const glm::dvec3& p) { return glm::dot(axis, glm::normalize(p - lp)); };
    auto radiance = [&](const glm::dvec3& p) {
        const glm::dvec3 d = lp - p;
        const double r2 = glm::dot(d, d);
        const double t = std::clamp((cdAt(p) - cosOut) / (cosIn - cosOut), 0.0, 1.0);
        return kRho / kPiD * 3.0 * t * t * (d.y / std::sqrt(r2)) / r2;
    };
    checkDirectAgainst(acc, cam, 0, radiance, "spot light direct", 32);

    // Zones: pixels whose whole footprint is inside the inner cone, in the t^2 ring, outside
    int zone[3] = {0, 0, 0};
    for (int y = 0; y < acc.height; ++y)
        for (int x = 0; x < acc.width; ++x) {
            double lo = 2.0, hi = -2.0;
            for (double v : {0.0, 1.0})
                for (double u : {0.0, 1.0}) {
                    const double cd = cdAt(planePoint(cam, x + u, y + v, 32, 32, 0.0));
                    lo = std::min(lo, cd);
                    hi = std::max(hi, cd);
                }
            if (lo >= cosIn) ++zone[0];
            if (lo > cosOut && hi < cosIn) ++zone[1];
            if (hi < cosOut - 1e-3) {
                ++zone[2];
                EXPECT_EQ(acc.mean(Layer::Direct, x, y, 0), 0.0) << x << "," << y;
            }
        }
    std::printf("[ measured ] spot zones: %d inner, %d falloff, %d outside pixels\n", zone[0],
                zone[1], zone[2]);
    EXPECT_GT(zone[0], 10);
    EXPECT_GT(zone[1], 10);
    EXPECT_GT(zone[2], 10);
}

TEST(CpuReferencePunctual, DirectionalLightIsUniform) {
    const Camera cam = lookDown({0.0f, 2.0f, 0.0f}, 60.0f);
    Scene s = planeScene(16, cam);
    Light sun;
    sun.type = LightType::Directional;
    sun.direction = glm::normalize(glm::vec3(0.3f, -1.0f, 0.2f));
    sun.intensity = {1.0f, 2.0f, 3.0f};
    sun.color = sun.intensity;
    s.lights.push_back(sun);
    const Accumulator acc = render(s, settingsWith(Estimator::Mis, 0), 4);
    const double cosTheta = -double(sun.direction.y);
    for (int c = 0; c < 3; ++c) {
        const double want = kRho / kPiD * sun.intensity[c] * cosTheta;
        for (int y = 0; y < acc.height; ++y)
            for (int x = 0; x < acc.width; ++x)
                ASSERT_NEAR(acc.mean(Layer::Direct, x, y, c), want, 1e-6 * want);
    }
}

// ---------------------------------------------------------------------------------------------
// Area light: a square emitter parallel above the plane, under every estimator
// ---------------------------------------------------------------------------------------------

TEST(CpuReferenceAreaLight, ParallelSquareFormFactorUnderEveryEstimator) {
    const float half = 0.25f, height = 1.0f;
    const glm::vec3 le(3.0f, 2.0f, 1.0f);
    const Camera cam = lookDown({0.0f, 0.5f, 0.0f}, 40.0f);
    Scene s = planeScene(12, cam);
    const uint32_t em = addMaterial(s, lambert(glm::vec3(0.0f), le));
    addHorizontalQuad(s, height, half, -1.0f, em);

    Estimate est[3];
    double expected = 0.0;
    const Estimator estimators[3] = {Estimator::Mis, Estimator::NeeOnly, Estimator::BsdfOnly};
    for (int i = 0; i < 3; ++i) {
        const Accumulator acc = render(s, settingsWith(estimators[i], 0), 2048);
        // L = rho / pi x E, E = pi Le F (Lambertian emitter)
        auto radiance = [&](const glm::dvec3& p) {
            return kRho * le.x * formFactorRect(p.x, p.z, -half, half, -half, half, height);
        };
        checkDirectAgainst(
            acc, cam, 0, radiance,
            (std::string("area light direct, ") + estimatorName(estimators[i])).c_str(), 8);
        est[i] = imageMean(acc, Layer::Direct, 0);
        expected = 0.0;
        for (int y = 0; y < acc.height; ++y)
            for (int x = 0; x < acc.width; ++x)
                expected += pixelAverage(cam, x, y, acc.width, acc.height, 8, radiance);
        expected /= double(acc.width * acc.height);
        // Emission is only seen from below the emitter's back: nothing here
        EXPECT_EQ(imageMean(acc, Layer::Emission, 0).mean, 0.0);
    }
    // The point below the centre: E = pi Le 4 F_corner (printed for docs/reference.md)
    std::printf("[ measured ] area light: F(centre) = %.6f, L(centre) = %.6f\n",
                4.0 * formFactorCorner(half, half, height),
                kRho * le.x * 4.0 * formFactorCorner(half, half, height));
    for (int i = 0; i < 3; ++i)
        for (int j = i + 1; j < 3; ++j) {
            const double sigma = std::hypot(est[i].sigma, est[j].sigma);
            EXPECT_LE(std::abs(est[i].mean - est[j].mean), 4.0 * sigma + 1e-5 * expected)
                << estimatorName(estimators[i]) << " vs " << estimatorName(estimators[j]);
        }
    // MIS must not be noisier than the worse of its two parts
    EXPECT_LE(est[0].sigma, std::max(est[1].sigma, est[2].sigma));
    std::printf("[ measured ] area light stderr: mis %.3g, nee %.3g, bsdf %.3g\n", est[0].sigma,
                est[1].sigma, est[2].sigma);
}

TEST(CpuReferenceAreaLight, GlossyPlaneAgreesWithQuadratureUnderEveryEstimator) {
    // A rough metal-dielectric mix sees the emitter's reflection: exercises the GGX sampling,
    // its pdf in the MIS weights and the glTF BRDF inside the integrator
    const float half = 0.25f, height = 1.0f;
    const glm::vec3 le(3.0f, 2.0f, 1.0f), albedo(0.8f, 0.7f, 0.6f);
    const float metallic = 0.5f, roughness = 0.3f;
    Scene s = emptyScene("glossy_plane", 10);
    Material glossy = lambert(albedo);
    glossy.metallic = metallic;
    glossy.roughness = roughness;
    addHorizontalQuad(s, 0.0f, 20.0f, 1.0f, addMaterial(s, glossy));
    addHorizontalQuad(s, height, half, -1.0f, addMaterial(s, lambert(glm::vec3(0.0f), le)));
    s.camera.position = {0.0f, 0.5f, 0.12f};
    s.camera.target = {0.0f, 0.0f, -0.05f};
    s.camera.up = {0.0f, 0.0f, -1.0f};
    s.camera.vfovRad = glm::radians(30.0f);
    const Camera& cam = s.camera;

    // L(p) = sum over emitter cells of f Le cos_x cos_y / d^2 dA (midpoint rule, 48 x 48)
    auto radiance = [&](const glm::dvec3& p) {
        const int n = 64;
        const double cell = 2.0 * half / n;
        const glm::vec3 wo = glm::normalize(glm::vec3(glm::dvec3(cam.position) - p));
        double sum = 0.0;
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i) {
                const glm::dvec3 y(-half + (i + 0.5) * cell, height, -half + (j + 0.5) * cell);
                const glm::dvec3 d = y - p;
                const double d2 = glm::dot(d, d);
                const glm::vec3 wi = glm::normalize(glm::vec3(d));
                const double cosX = wi.y, cosY = wi.y;
                const glm::vec3 f =
                    evalGltfBrdf({0.0f, 1.0f, 0.0f}, wi, wo, albedo, metallic, roughness);
                sum += f.x * le.x * cosX * cosY / d2 * cell * cell;
            }
        return sum;
    };
    Estimate est[3];
    const Estimator estimators[3] = {Estimator::Mis, Estimator::NeeOnly, Estimator::BsdfOnly};
    for (int i = 0; i < 3; ++i) {
        const Accumulator acc = render(s, settingsWith(estimators[i], 0), 8192);
        est[i] = imageMean(acc, Layer::Direct, 0);
    }
    double expected = 0.0;
    for (int y = 0; y < 10; ++y)
        for (int x = 0; x < 10; ++x)
            expected += pixelAverage(cam, x, y, 10, 10, 8, radiance);
    expected /= 100.0;
    for (int i = 0; i < 3; ++i) {
        // 0.5%: the quadratures (4 x 4 per pixel, 48 x 48 on the emitter) of a glossy lobe
        EXPECT_TRUE(agrees(est[i], expected, 4.0, 5e-3)) << estimatorName(estimators[i]);
        printMeasured((std::string("glossy area light, ") + estimatorName(estimators[i])).c_str(),
                      est[i].mean, est[i].sigma, expected);
        for (int j = i + 1; j < 3; ++j)
            EXPECT_LE(std::abs(est[i].mean - est[j].mean),
                      4.0 * std::hypot(est[i].sigma, est[j].sigma))
                << estimatorName(estimators[i]) << " vs " << estimatorName(estimators[j]);
    }
}

// ---------------------------------------------------------------------------------------------
// Layer bookkeeping, determinism, cancellation
// ---------------------------------------------------------------------------------------------

Scene smallCornell(int size) {
    Scene s = makeCornellBox(CornellBoxParams{});
    s.settings.width = size;
    s.settings.height = size;
    return s;
}

TEST(CpuReferenceLayers, LayersSumToFull) {
    const Accumulator acc = render(smallCornell(16), settingsWith(Estimator::Mis, 5), 16);
    double worst = 0.0;
    for (int y = 0; y < acc.height; ++y)
        for (int x = 0; x < acc.width; ++x)
            for (int c = 0; c < 3; ++c) {
                double parts = 0.0;
                for (int l = 1; l < kLayerCount; ++l)
                    parts += acc.mean(Layer(l), x, y, c);
                const double full = acc.mean(Layer::Full, x, y, c);
                const double rel = std::abs(full - parts) / std::max(std::abs(full), 1e-12);
                worst = std::max(worst, rel);
                EXPECT_LE(std::abs(full - parts), 1e-5 * std::abs(full) + 1e-12);
            }
    std::printf("[ measured ] max |full - sum(layers)| / full = %.2e\n", worst);
    EXPECT_GT(imageMean(acc, Layer::Bounce3Plus, 0).mean, 0.0);
}

bool sameSums(const Accumulator& a, const Accumulator& b) {
    return a.samples == b.samples && a.sum.size() == b.sum.size() &&
           std::memcmp(a.sum.data(), b.sum.data(), a.sum.size() * sizeof(double)) == 0 &&
           std::memcmp(a.sumSq.data(), b.sumSq.data(), a.sumSq.size() * sizeof(double)) == 0 &&
           a.replicate == b.replicate && a.replicateSumSq == b.replicateSumSq &&
           a.replicateOpen == b.replicateOpen;
}

void checkThreadsBatchesAndSeeds(SamplerKind sampler) {
    Scene scene = smallCornell(24);
    scene.lights.push_back(pointLight({0.3f, 0.4f, 0.3f}, glm::vec3(0.05f)));
    scene.computeCaps();
    ReferenceSettings st = settingsWith(Estimator::Mis, 4, 11);
    st.sampler = sampler;
    st.sobolReplicate = 2;       // replicates end inside and between the calls below
    st.rouletteStartBounce = 1;  // the roulette's draws are part of the stream too
    auto renderWith = [&](int threads, std::vector<uint32_t> batches, uint64_t seed) {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
        ReferenceSettings s = st;
        s.seed = seed;
        PathTracer tracer(scene, s);  // the BVH is built under the same limit
        Accumulator acc;
        acc.reset(24, 24);
        for (uint32_t b : batches)
            EXPECT_TRUE(tracer.addSamples(acc, b));
        return acc;
    };
    const Accumulator one = renderWith(1, {8}, 11);
    const Accumulator two = renderWith(2, {8}, 11);
    const Accumulator split = renderWith(2, {4, 4}, 11);
    const Accumulator uneven = renderWith(2, {1, 2, 5}, 11);
    const Accumulator other = renderWith(2, {8}, 12);
    EXPECT_TRUE(sameSums(one, two)) << "1 vs 2 threads";
    EXPECT_TRUE(sameSums(two, split)) << "8 vs 4 + 4 samples";
    EXPECT_TRUE(sameSums(two, uneven)) << "8 vs 1 + 2 + 5 samples";
    EXPECT_FALSE(sameSums(two, other)) << "another seed";
}

TEST(CpuReferenceDeterminism, ThreadsBatchesAndSeeds) {
    checkThreadsBatchesAndSeeds(SamplerKind::Independent);
}

TEST(CpuReferenceDeterminism, SobolThreadsBatchesAndSeeds) {
    checkThreadsBatchesAndSeeds(SamplerKind::Sobol);
}

// ---------------------------------------------------------------------------------------------
// Samplers (docs/reference.md, "Samplers")
// ---------------------------------------------------------------------------------------------

/** Cells of a 1D (256) and a 2D (16 x 16) grid holding other than exactly one of 256 samples. */
struct Strata {
    int badPixelPad = 0, badSelect = 0, badLight = 0, badLobe = 0;
};

Strata strataOf(SamplerKind kind, uint64_t pixel) {
    int pixelPad[16][16] = {}, light[16][16] = {}, select[256] = {}, lobe[256] = {};
    for (uint32_t s = 0; s < 256; ++s) {
        Sampler sm(7, pixel, s, kind);
        const glm::vec2 u = sm.get2D();     // the camera ray's pixel position
        const double d = sm.get1DDouble();  // light selection
        const glm::vec2 p = sm.get2D();     // point on the light
        const float l = sm.get1D();         // BSDF lobe
        ++pixelPad[int(u.x * 16)][int(u.y * 16)];
        ++select[int(d * 256)];
        ++light[int(p.x * 16)][int(p.y * 16)];
        ++lobe[int(l * 256)];
    }
    Strata st;
    for (int i = 0; i < 256; ++i) {
        st.badPixelPad += pixelPad[i / 16][i % 16] != 1;
        st.badLight += light[i / 16][i % 16] != 1;
        st.badSelect += select[i] != 1;
        st.badLobe += lobe[i] != 1;
    }
    return st;
}

TEST(CpuReferenceSampler, SobolDrawsAreStratifiedPerPixelAndLaterDrawsVary) {
    for (uint64_t pixel : {0ull, 12345ull, 1ull << 40}) {
        const Strata sobol = strataOf(SamplerKind::Sobol, pixel);
        EXPECT_EQ(sobol.badPixelPad, 0) << pixel;
        EXPECT_EQ(sobol.badSelect, 0) << pixel;
        EXPECT_EQ(sobol.badLight, 0) << pixel;
        EXPECT_EQ(sobol.badLobe, 0) << pixel;
        // i.i.d. uniforms leave about 256 / e empty cells: the check can tell them apart
        const Strata iid = strataOf(SamplerKind::Independent, pixel);
        EXPECT_GT(iid.badLight, 100) << pixel;
    }
    // Past the stratified draws the numbers are i.i.d. per sample, not shared by the pixel
    double sum = 0.0;
    int distinct = 0;
    float previous = -1.0f;
    for (uint32_t s = 0; s < 1024; ++s) {
        Sampler sm(7, 3, s, SamplerKind::Sobol);
        for (int i = 0; i < 8; ++i)
            sm.get1D();
        const float v = sm.get1D();
        sum += v;
        distinct += v != previous;
        previous = v;
    }
    EXPECT_EQ(distinct, 1024);
    EXPECT_NEAR(sum / 1024.0, 0.5, 4.0 * std::sqrt(1.0 / 12.0 / 1024.0));
}

TEST(CpuReferenceSampler, SobolDimension1TablesMatchTheDirectionNumbers) {
    // Sobol dimension 1 by its definition: x = xor of v_j over the set bits j of i
    auto direct = [](uint32_t i) {
        uint32_t x = 0;
        for (uint32_t v = 1u << 31; i != 0; i >>= 1, v ^= v >> 1)
            if (i & 1u) x ^= v;
        return x;
    };
    uint64_t state = 1;
    for (int k = 0; k < 100000; ++k) {
        const uint32_t i = k < 4096 ? uint32_t(k) : uint32_t(mix64(++state));
        ASSERT_EQ(sobolDimension1(i), direct(i)) << i;
        ASSERT_EQ(detail::kSobolDimension1Reversed(i), reverseBits32(direct(i))) << i;
    }
    // The first points of the (0, 2)-sequence: 1/2, 3/4, 1/4, 3/8 in dimension 1
    EXPECT_EQ(sobolDimension1(1), 0x80000000u);
    EXPECT_EQ(sobolDimension1(2), 0xc0000000u);
    EXPECT_EQ(sobolDimension1(3), 0x40000000u);
    EXPECT_EQ(sobolDimension1(4), 0xa0000000u);
}

TEST(CpuReferenceSampler, SobolReplicatesAreIndependentlyScrambledNets) {
    // Replicates of 64: samples [64r, 64r + 64) of a pixel are an 8 x 8-stratified net of their
    // own; two replicates are different point sets (their own scrambles)
    auto points = [](uint32_t replicate) {
        std::vector<glm::vec2> p;
        int cells[8][8] = {};
        for (uint32_t s = 64 * replicate; s < 64 * replicate + 64; ++s) {
            Sampler sm(7, 99, s, SamplerKind::Sobol, 6);
            sm.get2D();  // the camera pad
            p.push_back(sm.get2D());
            ++cells[int(p.back().x * 8)][int(p.back().y * 8)];
        }
        for (auto& row : cells)
            for (int c : row)
                EXPECT_EQ(c, 1) << "replicate " << replicate;
        return p;
    };
    const std::vector<glm::vec2> a = points(0), b = points(1), c = points(5);
    EXPECT_NE(a, b);
    EXPECT_NE(b, c);
    // Replicate 0 of 64 is the first 64 samples of the unreplicated sequence
    for (uint32_t s = 0; s < 64; ++s) {
        Sampler whole(7, 99, s, SamplerKind::Sobol);
        whole.get2D();
        EXPECT_EQ(whole.get2D(), a[s]);
    }
}

/** A 12 x 12 view of a plane under a square emitter: direct light through pixel centres, where
 *  Sobol's stratification pays most. */
Scene planeUnderSquareEmitter() {
    Scene s = planeScene(12, lookDown({0.0f, 0.5f, 0.0f}, 40.0f));
    addHorizontalQuad(s, 1.0f, 0.25f, -1.0f,
                      addMaterial(s, lambert(glm::vec3(0.0f), glm::vec3(3.0f, 2.0f, 1.0f))));
    return s;
}

TEST(CpuReferenceSampler, SobolErrorBarsFromReplicatesAreHonest) {
    // A plane under a square emitter, direct light through pixel centres (where Sobol pays
    // most). Over pixels, the squared difference of two seeds' images is twice the variance of
    // either; the stderr^2 of the replicates must match it, the i.i.d. formula over-estimates.
    const Scene s = planeUnderSquareEmitter();
    ReferenceSettings st = settingsWith(Estimator::Mis, 0);
    st.pixelFilter = PixelFilter::Center;
    st.sampler = SamplerKind::Sobol;
    st.sobolReplicate = 8;
    double diff2 = 0.0, replicateVar = 0.0, iidVar = 0.0;
    for (uint64_t seed = 1; seed <= 8; seed += 2) {
        st.seed = seed;
        const Accumulator a = render(s, st, 128);
        st.seed = seed + 1;
        const Accumulator b = render(s, st, 128);
        ASSERT_TRUE(a.replicateErrors());
        for (const Accumulator* acc : {&a, &b})
            for (int y = 0; y < acc->height; ++y)
                for (int x = 0; x < acc->width; ++x) {
                    const double e = acc->stdError(Layer::Direct, x, y, 0);
                    replicateVar += e * e / 2.0;
                    // The i.i.d. formula from the same sums
                    const size_t i = acc->index(Layer::Direct, x, y, 0);
                    const double n = double(acc->samples), m = acc->sum[i] / n;
                    iidVar += (acc->sumSq[i] - n * m * m) / (n - 1.0) / n / 2.0;
                }
        for (int y = 0; y < a.height; ++y)
            for (int x = 0; x < a.width; ++x) {
                const double d = a.mean(Layer::Direct, x, y, 0) - b.mean(Layer::Direct, x, y, 0);
                diff2 += d * d / 2.0;
            }
    }
    std::printf(
        "[ measured ] direct light, Sobol 128 spp in replicates of 8: variance from "
        "seed pairs %.4g, from replicates %.4g (ratio %.3f), i.i.d. formula %.4g "
        "(ratio %.3f)\n",
        diff2, replicateVar, replicateVar / diff2, iidVar, iidVar / diff2);
    EXPECT_GT(replicateVar / diff2, 0.75);
    EXPECT_LT(replicateVar / diff2, 1.33);
    EXPECT_GT(iidVar / diff2, 1.5);
}

TEST(CpuReferenceSampler, SobolHasLowerErrorThanIndependentUnderAnAreaLight) {
    // A plane under a square emitter, direct light through pixel centres: the error of 64 spp
    // against 8192 i.i.d. spp, summed over pixels, must drop with the stratified sampler.
    const Scene s = planeUnderSquareEmitter();
    ReferenceSettings st = settingsWith(Estimator::Mis, 0);
    st.pixelFilter = PixelFilter::Center;
    const Accumulator truth = render(s, st, 8192);
    auto sqError = [&](SamplerKind kind) {
        ReferenceSettings k = st;
        k.sampler = kind;
        k.seed = 3;
        const Accumulator acc = render(s, k, 64);
        double e = 0.0;
        for (int y = 0; y < acc.height; ++y)
            for (int x = 0; x < acc.width; ++x) {
                const double d =
                    acc.mean(Layer::Direct, x, y, 0) - truth.mean(Layer::Direct, x, y, 0);
                e += d * d;
            }
        return e;
    };
    const double iid = sqError(SamplerKind::Independent), sobol = sqError(SamplerKind::Sobol);
    std::printf("[ measured ] direct light, 64 spp: squared error sobol / independent = %.3f\n",
                sobol / iid);
    EXPECT_LT(sobol, 0.5 * iid);
}

TEST(CpuReferenceDeterminism, TexturedSceneWithOneOrTwoThreads) {
    // Sponza (66k triangles, textures): large enough for Embree to build its BVH in parallel
    Scene scene;
    try {
        scene = loadSceneFile(std::string(GILAB_SOURCE_DIR) + "/scenes/sponza.json");
    } catch (const Error& e) {
        GTEST_SKIP() << "shared scene not available: " << e.what();
    }
    scene.settings.width = 32;
    scene.settings.height = 18;
    std::printf("[ measured ] %s: %zu triangles, %zu textures\n", scene.name.c_str(),
                scene.triangleCount(), scene.textures.size());
    auto renderWith = [&](int threads) {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
        PathTracer tracer(scene, settingsWith(Estimator::Mis, 3));
        Accumulator acc;
        acc.reset(32, 18);
        EXPECT_TRUE(tracer.addSamples(acc, 2));
        return acc;
    };
    EXPECT_TRUE(sameSums(renderWith(1), renderWith(2)));
}

TEST(CpuReferenceDeterminism, CancelledBatchLeavesAccumulatorUnchanged) {
    Scene scene = smallCornell(16);
    PathTracer tracer(scene, settingsWith(Estimator::Mis, 2));
    Accumulator acc;
    acc.reset(16, 16);
    ASSERT_TRUE(tracer.addSamples(acc, 2));
    const Accumulator before = acc;
    std::atomic<bool> cancel{true};
    EXPECT_FALSE(tracer.addSamples(acc, 2, &cancel));
    EXPECT_TRUE(sameSums(acc, before));
    const RenderReport report = renderUntil(tracer, acc, StopCriteria{8, 0.0, 0.0}, &cancel);
    EXPECT_EQ(report.reason, StopReason::Cancelled);
    EXPECT_TRUE(sameSums(acc, before));
    Accumulator wrong;
    wrong.reset(8, 8);
    EXPECT_THROW(tracer.addSamples(wrong, 1), Error);
}

TEST(CpuReferenceDeterminism, PacketAndScalarCameraRaysAgree) {
    // Both camera-ray paths are valid estimators of the same image (hits may differ in ulps)
    Scene scene = smallCornell(16);
    setRayPackets(false);
    const Accumulator scalar = render(scene, settingsWith(Estimator::Mis, 1), 16);
    setRayPackets(true);
    const Accumulator packets = render(scene, settingsWith(Estimator::Mis, 1), 16);
    const Estimate a = imageMean(scalar, Layer::Full, 0), b = imageMean(packets, Layer::Full, 0);
    EXPECT_LE(std::abs(a.mean - b.mean), 1e-4 * a.mean + 4.0 * std::hypot(a.sigma, b.sigma));
    EXPECT_EQ(scalar.mean(Layer::Emission, 8, 1, 0), packets.mean(Layer::Emission, 8, 1, 0));
}

// ---------------------------------------------------------------------------------------------
// Alpha masks
// ---------------------------------------------------------------------------------------------

TEST(CpuReferenceAlpha, MaskedOccluderCastsNoShadow) {
    const Camera cam = lookDown({0.0f, 1.0f, 0.0f}, 120.0f);
    const glm::dvec3 lp(0.0, 3.0, 0.0);
    auto makeScene = [&](AlphaMode mode, float coverage, int texture) {
        Scene s = planeScene(16, cam);
        s.lights.push_back(pointLight(glm::vec3(lp), glm::vec3(4.0f)));
        Material occ = lambert(glm::vec3(0.5f));
        occ.baseColorFactor.a = coverage;
        occ.alphaMode = mode;
        occ.alphaCutoff = 0.5f;
        occ.baseColorTexture = texture;
        addHorizontalQuad(s, 1.5f, 0.5f, -1.0f, addMaterial(s, occ));  // u along +x
        return s;
    };
    auto lit = [&](const glm::dvec3& p) {
        const glm::dvec3 d = lp - p;
        const double r2 = glm::dot(d, d);
        return kRho / kPiD * 4.0 * (d.y / std::sqrt(r2)) / r2;
    };
    // Coverage 0.2 < cutoff 0.5: the quad does not exist for any ray
    const Accumulator masked =
        render(makeScene(AlphaMode::Mask, 0.2f, -1), settingsWith(Estimator::Mis, 0), 16);
    checkDirectAgainst(masked, cam, 0, lit, "alpha-masked occluder");
    // Control: the same quad opaque shadows the pixels under it (|x|, |z| < 1 on the plane)
    const Accumulator opaque =
        render(makeScene(AlphaMode::Opaque, 0.2f, -1), settingsWith(Estimator::Mis, 0), 4);
    EXPECT_EQ(opaque.mean(Layer::Direct, 8, 8, 0), 0.0);
    EXPECT_GT(opaque.mean(Layer::Direct, 0, 0, 0), 0.0);

    // Texture alpha: 2 x 1 texels, alpha 0 | 255, clamped: coverage = u-lerp, cut for u < 0.5
    Scene textured = makeScene(AlphaMode::Mask, 1.0f, 0);
    Texture t;
    t.name = "alpha_halves";
    t.width = 2;
    t.height = 1;
    t.rgba = {255, 255, 255, 0, 255, 255, 255, 255};
    t.wrapU = t.wrapV = WrapMode::ClampToEdge;
    textured.textures.push_back(t);
    const Accumulator half = render(textured, settingsWith(Estimator::Mis, 0), 4);
    int litCount = 0, darkCount = 0;
    for (int y = 0; y < 16; ++y)
        for (int x = 0; x < 16; ++x) {
            const glm::dvec3 p = planePoint(cam, x + 0.5, y + 0.5, 16, 16, 0.0);
            if (std::abs(p.z) > 0.8 || std::abs(p.x) > 0.9 || std::abs(p.x) < 0.2) continue;
            const double v = half.mean(Layer::Direct, x, y, 0);
            if (p.x < 0.0) {  // under the cut-out half
                EXPECT_GT(v, 0.0) << x << "," << y;
                ++litCount;
            } else {
                EXPECT_EQ(v, 0.0) << x << "," << y;
                ++darkCount;
            }
        }
    EXPECT_GT(litCount, 4);
    EXPECT_GT(darkCount, 4);
}

// ---------------------------------------------------------------------------------------------
// BSDF: the GLSL formula's properties, pdf normalisation and sampling consistency
// ---------------------------------------------------------------------------------------------

glm::vec3 dirFromAngles(float thetaDeg, float phiDeg) {
    const float t = glm::radians(thetaDeg), p = glm::radians(phiDeg);
    return {std::sin(t) * std::cos(p), std::sin(t) * std::sin(p), std::cos(t)};
}

TEST(CpuReferenceBsdf, LambertianRuleAndReciprocity) {
    const glm::vec3 n(0, 0, 1), albedo(0.2f, 0.5f, 0.9f);
    const glm::vec3 wo = dirFromAngles(40, 10), wi = dirFromAngles(60, 200);
    const glm::vec3 lambertF = evalGltfBrdf(n, wi, wo, albedo, 0.0f, 1.0f);
    for (int c = 0; c < 3; ++c)
        EXPECT_FLOAT_EQ(lambertF[c], albedo[c] / float(kPiD));
    EXPECT_NE(evalGltfBrdf(n, wi, wo, albedo, 0.0f, 0.999f).x, lambertF.x);  // glossy now
    EXPECT_EQ(evalGltfBrdf(n, -wi, wo, albedo, 0.0f, 1.0f).x, 0.0f);         // below: 0
    for (float rough : {0.0f, 0.2f, 0.7f})
        for (float metal : {0.0f, 0.4f, 1.0f}) {
            const glm::vec3 a = evalGltfBrdf(n, wi, wo, albedo, metal, rough);
            const glm::vec3 b = evalGltfBrdf(n, wo, wi, albedo, metal, rough);
            for (int c = 0; c < 3; ++c) {
                EXPECT_NEAR(a[c], b[c], 1e-5f * a[c]);
                EXPECT_TRUE(std::isfinite(a[c]));
            }
        }
}

TEST(CpuReferenceBsdf, PdfIntegratesToOneAndSamplingMatchesEval) {
    struct Case {
        float roughness, metallic, thetaO;
    };
    const Case cases[] = {{0.3f, 0.0f, 30.0f}, {0.5f, 1.0f, 60.0f}, {0.2f, 0.5f, 10.0f},
                          {0.8f, 0.0f, 75.0f}, {1.0f, 0.0f, 45.0f}, {0.05f, 1.0f, 40.0f}};
    const glm::vec3 n(0.0f, 0.0f, 1.0f), albedo(0.9f, 0.6f, 0.3f);
    for (const Case& k : cases) {
        const Bsdf bsdf(n, albedo, k.metallic, k.roughness);
        const glm::vec3 wo = dirFromAngles(k.thetaO, 30.0f);
        // Integral of the pdf over the sphere (uniform directions); skip very sharp lobes,
        // where uniform sampling cannot resolve the peak
        const int n1 = 400000;
        double pdfSum = 0.0, pdfSq = 0.0;
        double uniAlbedo = 0.0, uniSq = 0.0;
        for (int i = 0; i < n1; ++i) {
            Sampler s(3, uint64_t(i), 0);
            const glm::vec3 wi = sampleUniformSphere(s.get2D());
            const double p = bsdf.pdf(wo, wi) * 4.0 * kPiD;
            pdfSum += p;
            pdfSq += p * p;
            const double f = wi.z > 0.0f ? bsdf.eval(wo, wi).y * wi.z * 4.0 * kPiD : 0.0;
            uniAlbedo += f;
            uniSq += f * f;
        }
        auto estimate = [](double sum, double sumSq, int n) {
            const double m = sum / n;
            return Estimate{m, std::sqrt(std::max(0.0, sumSq / n - m * m) / n)};
        };
        const Estimate pdfInt = estimate(pdfSum, pdfSq, n1);
        const Estimate uni = estimate(uniAlbedo, uniSq, n1);
        // Albedo by importance sampling: E[f cos / pdf]; failed samples count 0
        const int n2 = 100000;
        double is = 0.0, isSq = 0.0;
        for (int i = 0; i < n2; ++i) {
            Sampler s(5, uint64_t(i), 0);
            BsdfSample bs;
            const float uLobe = s.get1D();
            double v = 0.0;
            if (bsdf.sample(wo, uLobe, s.get2D(), bs)) {
                EXPECT_FLOAT_EQ(bs.pdf, bsdf.pdf(wo, bs.wi));
                v = bs.f.y * bs.wi.z / bs.pdf;
            }
            is += v;
            isSq += v * v;
        }
        const Estimate imp = estimate(is, isSq, n2);
        if (k.roughness >= 0.2f) {
            EXPECT_TRUE(agrees(pdfInt, 1.0, 5.0, 2e-3)) << "roughness " << k.roughness;
            const double sigma = std::hypot(uni.sigma, imp.sigma);
            EXPECT_LE(std::abs(uni.mean - imp.mean), 5.0 * sigma + 2e-3 * uni.mean)
                << "roughness " << k.roughness << ": uniform " << uni.mean << " +- " << uni.sigma
                << ", importance " << imp.mean << " +- " << imp.sigma;
        }
        EXPECT_LE(imp.mean, 1.0 + 4.0 * imp.sigma);  // energy conservation (albedo <= 1)
        std::printf(
            "[ measured ] bsdf r=%.2f m=%.1f theta=%2.0f: int pdf %.4f +- %.4f, albedo "
            "uniform %.4f +- %.4f, sampled %.4f +- %.4f\n",
            k.roughness, k.metallic, k.thetaO, pdfInt.mean, pdfInt.sigma, uni.mean, uni.sigma,
            imp.mean, imp.sigma);
    }
}

// ---------------------------------------------------------------------------------------------
// Textures: scene.glsl's mip-0 bilinear rule
// ---------------------------------------------------------------------------------------------

TEST(CpuReferenceTexture, BilinearAfterSrgbDecodeWithWrapModes) {
    Texture t;
    t.name = "2x1";
    t.width = 2;
    t.height = 1;
    t.rgba = {0, 0, 0, 0, 255, 128, 64, 255};
    std::vector<Texture> textures(3, t);
    textures[1].wrapU = WrapMode::ClampToEdge;
    textures[2].wrapU = WrapMode::MirroredRepeat;
    textures[2].colorSpace = ColorSpace::Linear;
    const TextureLookup lookup(textures);
    auto srgb = [](int b) {
        const double c = b / 255.0;
        return c > 0.04045 ? std::pow((c + 0.055) / 1.055, 2.4) : c / 12.92;
    };
    // Texel centres: exact decoded values
    EXPECT_NEAR(lookup.sample(0, {0.75f, 0.5f}).y, srgb(128), 1e-6);
    EXPECT_NEAR(lookup.sample(0, {0.75f, 0.5f}).a, 1.0, 1e-7);
    // Half-way: the mean of the decoded texels, not the decoded mean
    EXPECT_NEAR(lookup.sample(0, {0.5f, 0.5f}).y, 0.5 * srgb(128), 1e-6);
    // u = 0 lies between texel 0 and (repeat) texel 1, or (clamp) texel 0
    EXPECT_NEAR(lookup.sample(0, {0.0f, 0.5f}).x, 0.5, 1e-6);
    EXPECT_NEAR(lookup.sample(1, {0.0f, 0.5f}).x, 0.0, 1e-7);
    // Mirrored, linear: u = -0.25 mirrors to 0.25 (texel 0's centre)
    EXPECT_NEAR(lookup.sample(2, {-0.25f, 0.5f}).y, 0.0, 1e-6);
    EXPECT_NEAR(lookup.sample(2, {1.25f, 0.5f}).y, 128.0 / 255.0, 1e-6);
    EXPECT_NEAR(lookup.average(0).x, 0.5, 1e-6);
}

// ---------------------------------------------------------------------------------------------
// Non-finite samples, stop criteria, error measures, description
// ---------------------------------------------------------------------------------------------

TEST(CpuReferenceGuard, NonFiniteSamplesAreCountedAndDropped) {
    const Camera cam = lookDown({0.0f, 2.0f, 0.0f}, 60.0f);
    for (float bad :
         {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity()}) {
        Scene s = planeScene(8, cam);
        s.lights.push_back(pointLight({0.0f, 1.0f, 0.0f}, glm::vec3(1.0f, bad, 1.0f)));
        RayStats stats;
        const Accumulator acc = render(s, settingsWith(Estimator::Mis, 1), 3, &stats);
        EXPECT_EQ(acc.nonFiniteSamples, 8u * 8u * 3u);  // every sample sees the plane
        EXPECT_EQ(stats.nonFiniteSamples, acc.nonFiniteSamples);
        EXPECT_EQ(acc.samples, 3u);
        for (double v : acc.sum)
            ASSERT_TRUE(std::isfinite(v));
        for (const ImageLayer& l : meanLayers(acc))
            EXPECT_TRUE(countNonFinite(l.image).allFinite()) << l.name;
    }
}

TEST(CpuReferenceStop, SamplesRelErrorAndCurve) {
    Scene scene = smallCornell(8);
    ReferenceSettings st = settingsWith(Estimator::Mis, 2);
    st.batchSamples = 3;
    PathTracer tracer(scene, st);
    Accumulator acc;
    acc.reset(8, 8);
    EXPECT_TRUE(std::isinf(meanRelativeStdError(acc)));
    RenderReport r = renderUntil(tracer, acc, StopCriteria{10, 0.0, 0.0});
    EXPECT_EQ(r.reason, StopReason::Samples);
    EXPECT_EQ(acc.samples, 10u);  // 3 + 3 + 3 + 1
    ASSERT_EQ(r.curve.size(), 4u);
    EXPECT_EQ(r.curve.back().samples, 10u);
    EXPECT_TRUE(std::isnan(r.curve.back().relMseVsLong));
    EXPECT_GT(r.rays.cameraRays, 0u);

    const Image longRef = meanLayers(acc)[0].image;
    const double target = 0.5 * r.relError;  // about 4x the samples
    r = renderUntil(tracer, acc, StopCriteria{0, target, 0.0}, nullptr, &longRef);
    EXPECT_EQ(r.reason, StopReason::RelError);
    EXPECT_LE(r.relError, target);
    EXPECT_GT(acc.samples, 10u);
    EXPECT_GE(r.curve.back().relMseVsLong, 0.0);
    EXPECT_THROW(renderUntil(tracer, acc, StopCriteria{}), Error);
}

TEST(CpuReferenceStop, RelativeMseDefinition) {
    Image a(2, 1, 3, 1.0f), b(2, 1, 3, 1.0f);
    EXPECT_EQ(relativeMse(a, b), 0.0);
    a.at(0, 0, 0) = 2.0f;  // (2 - 1)^2 / (1 + 0.01), averaged over 6 values
    EXPECT_NEAR(relativeMse(a, b), 1.0 / 1.01 / 6.0, 1e-12);
    EXPECT_THROW(relativeMse(a, Image(1, 1, 3)), Error);
}

// Corner seams at pixel centres (issue 16's robust ray offsets): the McGuire box's geometry
// [-1, 1] x [0, 2] x [-1, 1], open at +z, seen from (0, 1, 3.9) with a square image, puts the
// centre of pixel (r, r) exactly on the floor / right-wall edge (x = 1, y = 0) for the lower half
// of the image. A ray starting there must not start on or behind the adjacent wall: no seam
// pixel may be black or fall far below its four neighbours.
TEST(CpuReferenceSeams, CornerSeamPixelsAreNotDarkerThanTheirNeighbours) {
    Scene s = emptyScene("seam_box", 64);
    const uint32_t white = addMaterial(s, lambert(glm::vec3(0.7f), glm::vec3(0.0f)));
    const uint32_t green = addMaterial(s, lambert(glm::vec3(0.1f, 0.6f, 0.1f), glm::vec3(0.0f)));
    const uint32_t light = addMaterial(s, lambert(glm::vec3(0.0f), glm::vec3(10.0f)));
    appendQuad(s, {-1, 0, -1}, {1, 0, -1}, {1, 0, 1}, {-1, 0, 1}, {0, 1, 0}, white);    // floor
    appendQuad(s, {-1, 2, -1}, {1, 2, -1}, {1, 2, 1}, {-1, 2, 1}, {0, -1, 0}, white);   // ceiling
    appendQuad(s, {-1, 0, -1}, {1, 0, -1}, {1, 2, -1}, {-1, 2, -1}, {0, 0, 1}, white);  // back
    appendQuad(s, {1, 0, -1}, {1, 0, 1}, {1, 2, 1}, {1, 2, -1}, {-1, 0, 0}, green);     // right
    appendQuad(s, {-1, 0, -1}, {-1, 0, 1}, {-1, 2, 1}, {-1, 2, -1}, {1, 0, 0}, white);  // left
    appendQuad(s, {-0.25f, 1.99f, -0.25f}, {0.25f, 1.99f, -0.25f}, {0.25f, 1.99f, 0.25f},
               {-0.25f, 1.99f, 0.25f}, {0, -1, 0}, light);
    s.camera.position = {0.0f, 1.0f, 3.9f};
    s.camera.target = {0.0f, 1.0f, 0.0f};
    s.camera.up = {0.0f, 1.0f, 0.0f};
    s.camera.vfovRad = glm::radians(39.3f);
    s.computeCaps();
    ReferenceSettings st;
    st.maxBounces = 4;
    st.pixelFilter = PixelFilter::Center;
    PathTracer tracer(s, st);
    Accumulator acc;
    acc.reset(64, 64);
    ASSERT_TRUE(tracer.addSamples(acc, 256));
    auto lum = [&](int x, int y) {
        return luminance(float(acc.mean(Layer::Full, x, y, 0)),
                         float(acc.mean(Layer::Full, x, y, 1)),
                         float(acc.mean(Layer::Full, x, y, 2)));
    };
    auto err = [&](int x, int y) { return acc.stdError(Layer::Full, x, y, 1); };
    int checked = 0;
    for (int r = 40; r < 62; ++r) {  // the floor / right-wall edge, inside the box
        const double seam = lum(r, r);
        const double lowest =
            std::min({lum(r - 1, r), lum(r + 1, r), lum(r, r - 1), lum(r, r + 1)});
        EXPECT_GT(seam, 0.0) << "pixel (" << r << ", " << r << ") is black";
        EXPECT_GT(seam, 0.75 * lowest - 4.0 * err(r, r))
            << "pixel (" << r << ", " << r << "): " << seam << " vs neighbours >= " << lowest;
        if (r % 7 == 0)
            std::printf("seam pixel (%d, %d): %.4f, neighbours %.4f %.4f %.4f %.4f\n", r, r, seam,
                        lum(r - 1, r), lum(r + 1, r), lum(r, r - 1), lum(r, r + 1));
        ++checked;
    }
    EXPECT_EQ(checked, 22);
}

// Issue 27's case on the shared McGuire glTF: 256 x 256, pixel centres, 8 bounces. The centres of
// pixels (i, i), i = 196..250, lie on the floor / right-wall edge; they averaged 0.52 x their
// neighbours three to the left and three above (4 black) before hit points stepped back along
// the arriving ray and the centre filter took a 2^-10 px footprint (renderer version 4).
TEST(CpuReferenceSeams, McGuireBoxDiagonalIsNotDark) {
    Scene s;
    try {
        s = loadSceneFile(std::string(GILAB_SOURCE_DIR) + "/scenes/cornell_box_gltf.json");
    } catch (const Error& e) {
        GTEST_SKIP() << "shared scene not available: " << e.what();
    }
    s.settings.width = s.settings.height = 256;
    ReferenceSettings st;
    st.maxBounces = 8;
    st.pixelFilter = PixelFilter::Center;
    PathTracer tracer(s, st);
    Accumulator acc;
    acc.reset(256, 256);
    ASSERT_TRUE(tracer.addSamples(acc, 256));
    auto lum = [&](int x, int y) {
        return luminance(float(acc.mean(Layer::Full, x, y, 0)),
                         float(acc.mean(Layer::Full, x, y, 1)),
                         float(acc.mean(Layer::Full, x, y, 2)));
    };
    double diagonal = 0.0, neighbours = 0.0;
    for (int i = 196; i <= 250; ++i) {
        EXPECT_GT(lum(i, i), 0.0) << "pixel (" << i << ", " << i << ") is black";
        diagonal += lum(i, i);
        neighbours += 0.5 * (lum(i - 3, i) + lum(i, i - 3));
    }
    std::printf("[ measured ] McGuire box 256^2 diagonal / neighbours: %.3f\n",
                diagonal / neighbours);
    EXPECT_GE(diagonal / neighbours, 0.9);
}

TEST(CpuReferenceStop, DescriptionNamesEverySetting) {
    Scene scene = smallCornell(8);
    ReferenceSettings st = settingsWith(Estimator::NeeOnly, 9, 42);
    st.rouletteStartBounce = 3;
    PathTracer tracer(scene, st);
    const std::string d = tracer.toString();
    const std::string version = "v" + std::to_string(kRendererVersion);
    for (const char* part :
         {version.c_str(), "estimator: nee", "max_bounces: 9", "roulette_start_bounce: 3",
          "seed: 42", "batch_samples: 16",
          "pixel filter: ", "ray_origins: ", "render_space: camera", "embree: 3."})
        EXPECT_NE(d.find(part), std::string::npos) << part << " in\n" << d;
    // One description of the pixel filter, the one in use (it was also a fixed "box" line)
    EXPECT_EQ(d.find("pixel_filter:"), std::string::npos) << d;
    EXPECT_THROW(PathTracer(scene, settingsWith(Estimator::Mis, -1)), Error);
}

}  // namespace
}  // namespace gilab::ref

// ---------------------------------------------------------------------------------------------
// Throughput (disabled; docs/reference.md "Throughput"):
//   build-ref/tests/test_reference --gtest_also_run_disabled_tests --gtest_filter='*Throughput*'
// ---------------------------------------------------------------------------------------------

namespace gilab::ref {
namespace {

void measureThroughput(const Scene& scene, const ReferenceSettings& st, uint32_t spp) {
    PathTracer tracer(scene, st);
    for (bool packets : {true, false}) {
        setRayPackets(packets);
        Accumulator acc;
        acc.reset(scene.settings.width, scene.settings.height);
        tracer.addSamples(acc, 1);  // warm-up
        const RayStats before = tracer.stats();
        const std::clock_t cpuBefore = std::clock();
        tracer.addSamples(acc, spp);
        const double cpuSeconds = double(std::clock() - cpuBefore) / CLOCKS_PER_SEC;
        const RayStats& after = tracer.stats();
        const double seconds = after.seconds - before.seconds;
        const double rays = double(after.totalRays() - before.totalRays());
        std::printf(
            "[ measured ] %-12s %dx%d B=%-2d %s: %3u spp in %.2f s wall, %.2f s CPU; "
            "%.2f Mrays/s wall, %.2f Mrays per CPU-s (%.0f%% shadow rays)\n",
            scene.name.c_str(), scene.settings.width, scene.settings.height, st.maxBounces,
            packets ? "camera rtcIntersect16" : "camera rtcIntersect1 ", spp, seconds, cpuSeconds,
            rays / seconds * 1e-6, rays / cpuSeconds * 1e-6,
            100.0 * double(after.shadowRays - before.shadowRays) / rays);
    }
    setRayPackets(true);
}

// Center: every camera ray goes through the pixel centre, so the emitter seen directly covers a
// pixel fully or not at all; Box averages over the pixel and gives fractional edge pixels.
TEST(CpuReferencePixelFilter, CenterSamplesPixelCentresBoxAveragesThePixel) {
    Scene scene = makeBuiltinDefaultScene();
    scene.settings.width = 24;
    scene.settings.height = 24;
    auto fractionalPixels = [&](PixelFilter filter) {
        ReferenceSettings settings;
        settings.maxBounces = 0;
        settings.pixelFilter = filter;
        PathTracer tracer(scene, settings);
        Accumulator acc;
        acc.reset(scene.settings.width, scene.settings.height);
        tracer.addSamples(acc, 64);
        int fractional = 0, lit = 0;
        for (int y = 0; y < acc.height; ++y)
            for (int x = 0; x < acc.width; ++x) {
                const double v = acc.mean(Layer::Emission, x, y, 0);
                if (v > 1e-6) ++lit;
                if (v > 1e-6 && std::abs(v - 17.0) > 1e-4) ++fractional;
            }
        EXPECT_GT(lit, 0);
        return fractional;
    };
    EXPECT_EQ(fractionalPixels(PixelFilter::Center), 0);
    EXPECT_GT(fractionalPixels(PixelFilter::Box), 0);
}

TEST(CpuReferenceThroughput, DISABLED_CornellAndSponza) {
    Scene cornell = makeCornellBox(CornellBoxParams{});
    cornell.settings.width = cornell.settings.height = 256;
    measureThroughput(cornell, ReferenceSettings{}, 16);
    ReferenceSettings direct;
    direct.maxBounces = 0;
    measureThroughput(cornell, direct, 64);
    try {
        Scene sponza = loadSceneFile(std::string(GILAB_SOURCE_DIR) + "/scenes/sponza.json");
        measureThroughput(sponza, ReferenceSettings{}, 8);
    } catch (const Error& e) {
        std::printf("sponza not available: %s\n", e.what());
    }
}

}  // namespace
}  // namespace gilab::ref

namespace gilab::ref {
namespace {

/** A 2 x 2 floor (albedo 0.5) and one light. */
Scene floorUnder(const Light& light) {
    Scene s;
    s.name = "floor";
    s.sourcePath = "<test>";
    appendLambertianMaterial(s, "grey", glm::vec3(0.5f));
    appendQuad(s, {-1, 0, -1}, {1, 0, -1}, {1, 0, 1}, {-1, 0, 1}, {0, 1, 0}, 0);
    s.lights.push_back(light);
    s.computeCaps();
    return s;
}

// `gilab bench light-power` (issue 43's control for what voxels hold): known fluxes.
TEST(CpuLightPower, PointSpotAndSunFluxesMatchTheirClosedForms) {
    Light point;
    point.type = LightType::Point;
    point.position = {0.0f, 1.0f, 0.0f};
    point.intensity = glm::vec3(2.0f);
    // A point light 1 above a 2 x 2 floor: the floor subtends 2 pi / 3 sr (the solid angle of
    // a square of half-side a at height h: 4 asin(a^2 / (a^2 + h^2)) = 4 asin(1 / 2))
    ref::LightPower p = ref::punctualLightPower(floorUnder(point), 1u << 18).front();
    EXPECT_NEAR(p.emittedW, 2.0 * 4.0 * kPiD, 1e-3);
    EXPECT_NEAR(p.incidentW, 2.0 * 4.0 * std::asin(0.5), 2e-3 * p.incidentW);
    EXPECT_NEAR(p.reflectedW, 0.5 * p.incidentW, 1e-9 * p.incidentW);
    // A spot with a hard 30-degree cone pointing down: all of it lands on the floor
    Light spot = point;
    spot.type = LightType::Spot;
    spot.direction = {0.0f, -1.0f, 0.0f};
    spot.innerConeRad = spot.outerConeRad = float(kPiD / 6.0);
    p = ref::punctualLightPower(floorUnder(spot), 1u << 16).front();
    const double cone = 2.0 * kPiD * (1.0 - std::cos(kPiD / 6.0));
    EXPECT_NEAR(p.incidentW, 2.0 * cone, 1e-3 * p.incidentW);
    EXPECT_NEAR(p.emittedW, p.incidentW, 1e-9 * p.incidentW);
    // A sun straight down with E = 3 W/m^2: the floor's 4 m^2
    Light sun;
    sun.type = LightType::Directional;
    sun.direction = {0.0f, -1.0f, 0.0f};
    sun.intensity = glm::vec3(3.0f);
    p = ref::punctualLightPower(floorUnder(sun), 1u << 18).front();
    EXPECT_NEAR(p.incidentW, 12.0, 0.01 * 12.0);
    EXPECT_NEAR(p.reflectedW, 6.0, 0.01 * 6.0);
}

}  // namespace
}  // namespace gilab::ref
