// Shared passes (G-buffer, shadow maps, area-light samples, direct light) against closed forms.
// Every test runs on the Vulkan device with validation on and fails on any validation message.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <glm/glm.hpp>
#include "tests/gpu_test_fixture.h"

#include "core/gpu/gpu_scene.h"
#include "core/passes/emitter_samples.h"
#include "core/passes/shadow_cascades.h"
#include "core/passes/shared_passes.h"
#include "core/scene/mesh_builder.h"
#include "core/scene/procedural_cornell.h"
#include "core/scene/scene.h"
#include "core/vk/context.h"
#include "core/vk/timer.h"

namespace gilab {
namespace {

constexpr float kPi = 3.14159265358979f;
constexpr uint32_t kSize = 96;
constexpr float kAlbedo = 0.5f;

// ---------------------------------------------------------------------------------------------
// Scenes and rendering
// ---------------------------------------------------------------------------------------------

Material diffuse(glm::vec3 albedo) {
    Material m;
    m.baseColorFactor = glm::vec4(albedo, 1.0f);
    return m;
}

/** A horizontal square [-h, h]^2 at height y, facing `facing` (+y or -y). */
void addHorizontalQuad(Scene& s, float y, glm::vec2 lo, glm::vec2 hi, float facingY, uint32_t m) {
    appendQuad(s, {lo.x, y, lo.y}, {hi.x, y, lo.y}, {hi.x, y, hi.y}, {lo.x, y, hi.y},
               {0.0f, facingY, 0.0f}, m);
}

/** The big diffuse plane y = 0 (albedo 0.5, facing up) that every test lights. */
Scene planeScene(float halfSize = 6.0f) {
    Scene s;
    s.name = "test_plane";
    s.sourcePath = "<test>";
    s.materials.push_back(diffuse(glm::vec3(kAlbedo)));
    addHorizontalQuad(s, 0.0f, glm::vec2(-halfSize), glm::vec2(halfSize), 1.0f, 0);
    return s;
}

Camera topCamera(float height = 3.0f) {
    Camera c;
    c.position = {0.0f, height, 0.0f};
    c.target = {0.0f, 0.0f, 0.0f};
    c.up = {0.0f, 0.0f, -1.0f};
    c.vfovRad = 1.0471976f;  // 60 deg: covers |x|, |z| < 0.577 * height
    return c;
}

Camera lookAt(glm::vec3 eye, glm::vec3 target, glm::vec3 up = {0.0f, 1.0f, 0.0f}) {
    Camera c;
    c.position = eye;
    c.target = target;
    c.up = up;
    c.vfovRad = 1.0471976f;
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

/** Read-back layers of one frame (RGBA each). */
struct Frame {
    uint32_t width = 0, height = 0;
    std::vector<float> position, normal, albedo, material, emission, direct;
    std::vector<std::string> skipped;
    std::vector<PassLight> lights;
    std::vector<vk::GpuLight> gpuLights;

    glm::vec4 at(const std::vector<float>& layer, uint32_t x, uint32_t y) const {
        const float* p = &layer[(size_t(y) * width + x) * 4];
        return {p[0], p[1], p[2], p[3]};
    }
};

class GpuPassesTest : public test::ValidatedGpuTest {
protected:
    Frame render(Scene scene, const Camera& camera, const SharedPassSettings& settings = {},
                 uint32_t width = kSize, uint32_t height = kSize) {
        scene.computeCaps();
        vk::GpuScene gpuScene(*m_ctx, scene);
        SharedPasses passes(*m_ctx, gpuScene, width, height, settings);
        m_ctx->submitAndWait([&](VkCommandBuffer cmd) { passes.record(cmd, camera); });
        Frame f;
        f.width = width;
        f.height = height;
        GBuffer& g = passes.gbuffer();
        f.position = g.position.readbackFloat(*m_ctx);
        f.normal = g.normal.readbackFloat(*m_ctx);
        f.albedo = g.albedo.readbackFloat(*m_ctx);
        f.material = g.material.readbackFloat(*m_ctx);
        f.emission = g.emission.readbackFloat(*m_ctx);
        f.direct = passes.direct().readbackFloat(*m_ctx);
        f.skipped = passes.skippedPasses();
        f.lights = passes.shadows().lights();
        f.gpuLights = gpuScene.gpuLights();
        return f;
    }
};

/** Measured irradiance E = Lo * pi / albedo of a Lambertian pixel (per channel). */
glm::vec3 measuredIrradiance(const Frame& f, uint32_t x, uint32_t y) {
    return glm::vec3(f.at(f.direct, x, y)) * kPi / kAlbedo;
}

float relError(float got, float want) {
    return std::abs(got - want) / std::abs(want);
}

/** Max relative error over the channels where `want` > 0. */
float relError(glm::vec3 got, glm::vec3 want) {
    float e = 0.0f;
    for (int c = 0; c < 3; ++c) {
        if (want[c] > 0.0f) e = std::max(e, relError(got[c], want[c]));
    }
    return e;
}

bool onPlane(const Frame& f, uint32_t x, uint32_t y) {
    glm::vec4 p = f.at(f.position, x, y);
    return p.w > 0.0f && std::abs(p.y) < 1e-4f;
}

// ---------------------------------------------------------------------------------------------
// Analytic references
// ---------------------------------------------------------------------------------------------

/** E = I cos(theta) / r^2 on the plane y = 0 (normal +y). */
glm::vec3 pointIrradiance(const Light& l, glm::vec3 p) {
    glm::vec3 d = l.position - p;
    float r2 = glm::dot(d, d);
    float cosTheta = std::max(d.y, 0.0f) / std::sqrt(r2);
    return l.intensity * cosTheta / r2;
}

/** glTF KHR_lights_punctual spot falloff (t^2). */
float spotFactor(const Light& l, glm::vec3 p) {
    float cd = glm::dot(glm::normalize(l.direction), glm::normalize(p - l.position));
    float ci = std::cos(l.innerConeRad), co = std::cos(l.outerConeRad);
    float t = std::clamp((cd - co) / (ci - co), 0.0f, 1.0f);
    return t * t;
}

/**
 * Differential-area-to-parallel-rectangle form factor for a rectangle with one corner right
 * above the receiver: sides a, b at height c (Howell's catalogue of configuration factors, B-3):
 *   F = 1/(2 pi) [ X/sqrt(1+X^2) atan(Y/sqrt(1+X^2)) + Y/sqrt(1+Y^2) atan(X/sqrt(1+Y^2)) ]
 * with X = a/c, Y = b/c.
 */
double cornerFormFactor(double a, double b, double c) {
    double x = a / c, y = b / c;
    double sx = std::sqrt(1.0 + x * x), sy = std::sqrt(1.0 + y * y);
    return (x / sx * std::atan(y / sx) + y / sy * std::atan(x / sy)) / (2.0 * M_PI);
}

/** Signed corner term for a receiver at the origin and a corner at (x, z). */
double signedCorner(double x, double z, double c) {
    double s = (x < 0 ? -1.0 : 1.0) * (z < 0 ? -1.0 : 1.0);
    return s * cornerFormFactor(std::abs(x), std::abs(z), c);
}

/** Form factor from a point of y = 0 (normal +y) to the rectangle [x0,x1]x[z0,z1] at y = c. */
double rectangleFormFactor(glm::vec3 p, glm::vec2 lo, glm::vec2 hi, double c) {
    double x0 = lo.x - p.x, x1 = hi.x - p.x, z0 = lo.y - p.z, z1 = hi.y - p.z;
    return signedCorner(x1, z1, c) - signedCorner(x0, z1, c) - signedCorner(x1, z0, c) +
           signedCorner(x0, z0, c);
}

/** The glTF 2.0 Appendix B BRDF, written out on the CPU (same formulas as brdf.glsl). */
glm::vec3 gltfBrdf(glm::vec3 n, glm::vec3 l, glm::vec3 v, glm::vec3 albedo, float metallic,
                   float roughness) {
    double nl = glm::dot(n, l), nv = std::abs(glm::dot(n, v));
    glm::dvec3 h = glm::normalize(glm::dvec3(l) + glm::dvec3(v));
    double nh = glm::dot(glm::dvec3(n), h), vh = glm::dot(glm::dvec3(v), h);
    double a = std::max(double(roughness) * roughness, 1e-3), a2 = a * a;
    double d = a2 / (M_PI * std::pow(nh * nh * (a2 - 1.0) + 1.0, 2.0));
    double vis = 0.5 / (nl * std::sqrt(nv * nv * (1.0 - a2) + a2) +
                        nv * std::sqrt(nl * nl * (1.0 - a2) + a2));
    double specular = d * vis;
    double w = std::pow(1.0 - std::abs(vh), 5.0);
    glm::dvec3 base(albedo);
    double fd = 0.04 + 0.96 * w;
    glm::dvec3 fm = base + (glm::dvec3(1.0) - base) * w;
    glm::dvec3 dielectric = (1.0 - fd) * base / M_PI + fd * specular;
    glm::dvec3 metal = fm * specular;
    return glm::vec3(dielectric * (1.0 - metallic) + metal * double(metallic));
}

// ---------------------------------------------------------------------------------------------
// G-buffer
// ---------------------------------------------------------------------------------------------

TEST_F(GpuPassesTest, GBufferValuesExactAtPixelCentresAndBackgroundZero) {
    Scene s = planeScene(1.0f);  // smaller than the view: background around it
    s.materials[0].baseColorFactor = glm::vec4(0.25f, 0.5f, 0.75f, 1.0f);
    s.materials[0].metallic = 0.3f;
    s.materials[0].roughness = 0.6f;
    const Camera cam = topCamera();
    Frame f = render(s, cam);

    int covered = 0, background = 0;
    float maxPosError = 0.0f;
    for (uint32_t y = 0; y < f.height; ++y) {
        for (uint32_t x = 0; x < f.width; ++x) {
            Ray ray = cam.primaryRay(float(x) + 0.5f, float(y) + 0.5f, int(f.width), int(f.height));
            glm::vec3 hit = ray.origin + ray.direction * (-ray.origin.y / ray.direction.y);
            glm::vec4 pos = f.at(f.position, x, y);
            bool inside = std::abs(hit.x) < 0.99f && std::abs(hit.z) < 0.99f;
            bool outside = std::abs(hit.x) > 1.01f || std::abs(hit.z) > 1.01f;
            if (inside) {
                ++covered;
                ASSERT_EQ(pos.w, 1.0f);
                maxPosError = std::max(maxPosError, glm::length(glm::vec3(pos) - hit));
                EXPECT_EQ(f.at(f.normal, x, y), glm::vec4(0, 1, 0, 1));
                EXPECT_EQ(f.at(f.albedo, x, y), glm::vec4(0.25f, 0.5f, 0.75f, 0.6f));
                glm::vec4 m = f.at(f.material, x, y);
                EXPECT_FLOAT_EQ(m.x, 0.3f);
                EXPECT_FLOAT_EQ(m.y, 0.6f);
                EXPECT_EQ(uint32_t(m.z), uint32_t(vk::kMaterialGlossy));
                EXPECT_TRUE(m.w == 1.0f || m.w == 2.0f);
                EXPECT_EQ(f.at(f.emission, x, y), glm::vec4(0.0f));
            } else if (outside) {
                ++background;
                for (const auto* layer :
                     {&f.position, &f.normal, &f.albedo, &f.material, &f.emission, &f.direct}) {
                    ASSERT_EQ(f.at(*layer, x, y), glm::vec4(0.0f)) << x << "," << y;
                }
            }
        }
    }
    std::printf("gbuffer: %d covered, %d background pixels, max position error %.3g m\n", covered,
                background, maxPosError);
    EXPECT_GT(covered, 1000);
    EXPECT_GT(background, 1000);
    EXPECT_LT(maxPosError, 1e-5f);

    // Linear depth = distance along the forward axis = camera height on this plane
    Image depth = computeLinearDepth(f.position, f.width, f.height, cam);
    EXPECT_NEAR(depth.at(int(f.width / 2), int(f.height / 2), 0), 3.0f, 1e-5f);
    EXPECT_EQ(depth.at(0, 0, 0), 0.0f);
}

TEST_F(GpuPassesTest, GBufferNormalFacesViewerAndEmissionOnlyOnFront) {
    // Single-sided emitter facing down, seen from above (its back) and from below (its front)
    Scene s = planeScene();
    Material e = diffuse(glm::vec3(0.0f));
    e.emissiveFactor = {4.0f, 2.0f, 1.0f};
    s.materials.push_back(e);
    addHorizontalQuad(s, 1.0f, glm::vec2(-0.5f), glm::vec2(0.5f), -1.0f, 1);
    SharedPassSettings settings;
    settings.areaLightSamples = 0;

    Frame above = render(s, topCamera(2.0f), settings);
    glm::vec4 n = above.at(above.normal, kSize / 2, kSize / 2);
    EXPECT_EQ(n, glm::vec4(0, 1, 0, 0));  // flipped to the viewer, back face seen
    EXPECT_EQ(above.at(above.emission, kSize / 2, kSize / 2), glm::vec4(0.0f));

    Frame below = render(s, lookAt({0.0f, 0.2f, 0.0f}, {0.0f, 1.0f, 0.0f}, {0, 0, -1}), settings);
    EXPECT_EQ(below.at(below.normal, kSize / 2, kSize / 2), glm::vec4(0, -1, 0, 1));
    EXPECT_EQ(below.at(below.emission, kSize / 2, kSize / 2), glm::vec4(4.0f, 2.0f, 1.0f, 0.0f));
    EXPECT_EQ(below.at(below.direct, kSize / 2, kSize / 2), glm::vec4(0, 0, 0, 1));
}

// ---------------------------------------------------------------------------------------------
// Punctual lights, unoccluded (shadow maps on: any acne shows up as an error)
// ---------------------------------------------------------------------------------------------

TEST_F(GpuPassesTest, PointLightMatchesInverseSquareCosine) {
    Scene s = planeScene();
    Light light = pointLight({0.3f, 1.0f, -0.2f}, {10.0f, 5.0f, 2.5f});
    s.lights.push_back(light);
    Frame f = render(s, topCamera());

    float maxErr = 0.0f;
    int checked = 0;
    for (uint32_t y = 0; y < f.height; ++y) {
        for (uint32_t x = 0; x < f.width; ++x) {
            if (!onPlane(f, x, y)) continue;
            glm::vec3 want = pointIrradiance(light, glm::vec3(f.at(f.position, x, y)));
            maxErr = std::max(maxErr, relError(measuredIrradiance(f, x, y), want));
            ++checked;
        }
    }
    std::printf("point light: %d pixels, max relative error %.3g\n", checked, maxErr);
    EXPECT_GE(checked, 16);
    EXPECT_LT(maxErr, 0.01f);
}

TEST_F(GpuPassesTest, SpotLightFollowsConeFalloff) {
    Scene s = planeScene();
    Light light;
    light.type = LightType::Spot;
    light.position = {0.1f, 1.5f, 0.0f};
    light.direction = glm::normalize(glm::vec3(0.1f, -1.0f, 0.05f));
    light.intensity = {20.0f, 20.0f, 20.0f};
    light.color = light.intensity;
    light.innerConeRad = 0.35f;
    light.outerConeRad = 0.6f;
    s.lights.push_back(light);
    Frame f = render(s, topCamera());

    float maxInner = 0.0f, maxFalloff = 0.0f, maxOutside = 0.0f;
    int inner = 0, falloff = 0, outside = 0;
    const float ci = std::cos(light.innerConeRad), co = std::cos(light.outerConeRad);
    for (uint32_t y = 0; y < f.height; ++y) {
        for (uint32_t x = 0; x < f.width; ++x) {
            if (!onPlane(f, x, y)) continue;
            glm::vec3 p(f.at(f.position, x, y));
            float cd = glm::dot(light.direction, glm::normalize(p - light.position));
            glm::vec3 got = measuredIrradiance(f, x, y);
            glm::vec3 want = pointIrradiance(light, p) * spotFactor(light, p);
            if (cd > ci) {
                maxInner = std::max(maxInner, relError(got, want));
                ++inner;
            } else if (cd < co) {
                maxOutside = std::max(maxOutside, std::abs(got.x));
                ++outside;
            } else if (cd > co + 0.02f * (ci - co)) {  // t^2 well above zero
                maxFalloff = std::max(maxFalloff, relError(got, want));
                ++falloff;
            }
        }
    }
    std::printf(
        "spot: inner %d px max rel %.3g, falloff %d px max rel %.3g, outside %d px max "
        "%.3g\n",
        inner, maxInner, falloff, maxFalloff, outside, maxOutside);
    EXPECT_GE(inner, 16);
    EXPECT_GE(falloff, 16);
    EXPECT_GE(outside, 16);
    EXPECT_LT(maxInner, 0.01f);
    EXPECT_LT(maxFalloff, 0.01f);
    EXPECT_EQ(maxOutside, 0.0f);
}

TEST_F(GpuPassesTest, DirectionalLightIsUniform) {
    Scene s = planeScene();
    Light light;
    light.type = LightType::Directional;
    light.direction = glm::normalize(glm::vec3(0.3f, -1.0f, 0.2f));
    light.intensity = {2.0f, 3.0f, 4.0f};
    light.color = light.intensity;
    s.lights.push_back(light);
    Frame f = render(s, topCamera());

    const glm::vec3 want = light.intensity * -light.direction.y;
    float maxErr = 0.0f;
    int checked = 0;
    for (uint32_t y = 0; y < f.height; ++y) {
        for (uint32_t x = 0; x < f.width; ++x) {
            if (!onPlane(f, x, y)) continue;
            maxErr = std::max(maxErr, relError(measuredIrradiance(f, x, y), want));
            ++checked;
        }
    }
    std::printf("directional: %d pixels, max relative error %.3g\n", checked, maxErr);
    EXPECT_EQ(checked, int(kSize * kSize));
    EXPECT_LT(maxErr, 0.01f);
}

/** Analytic E on the plane y = 0 for an unoccluded light (point, spot or directional). */
glm::vec3 planeIrradiance(const Light& l, glm::vec3 p) {
    if (l.type == LightType::Directional) return l.intensity * std::max(-l.direction.y, 0.0f);
    glm::vec3 e = pointIrradiance(l, p);
    return l.type == LightType::Spot ? e * spotFactor(l, p) : e;
}

TEST_F(GpuPassesTest, NoShadowAcneAtGrazingAngles) {
    // Low lights: the plane is lit from cos(theta) = 1 down to grazing angles
    std::vector<Light> lights;
    for (glm::vec3 p : {glm::vec3(0.0f, 0.3f, 0.0f), glm::vec3(2.0f, 0.2f, 1.0f),
                        glm::vec3(-0.5f, 0.05f, 0.3f)}) {
        lights.push_back(pointLight(p, glm::vec3(1.0f)));
    }
    Light spot;
    spot.type = LightType::Spot;
    spot.position = {-1.5f, 0.1f, 0.0f};
    spot.direction = glm::normalize(glm::vec3(1.0f, -0.08f, 0.0f));
    spot.outerConeRad = 0.8f;
    spot.innerConeRad = 0.7f;
    lights.push_back(spot);
    for (float dy : {-0.05f, -0.3f}) {
        Light sun;
        sun.type = LightType::Directional;
        sun.direction = glm::normalize(glm::vec3(1.0f, dy, 0.4f));
        lights.push_back(sun);
    }
    for (const Light& light : lights) {
        Scene s = planeScene();
        s.lights.push_back(light);
        Frame f = render(s, topCamera());
        float maxErr = 0.0f;
        int checked = 0;
        for (uint32_t y = 0; y < f.height; ++y) {
            for (uint32_t x = 0; x < f.width; ++x) {
                if (!onPlane(f, x, y)) continue;
                glm::vec3 q(f.at(f.position, x, y));
                glm::vec3 want = planeIrradiance(light, q);
                if (want.x <= 1e-6f) continue;
                glm::vec3 d = light.type == LightType::Directional
                                  ? -light.direction
                                  : glm::normalize(light.position - q);
                if (d.y < 0.02f) continue;  // beyond 88.9 deg
                maxErr = std::max(maxErr, relError(measuredIrradiance(f, x, y), want));
                ++checked;
            }
        }
        glm::vec3 p = light.type == LightType::Directional ? light.direction : light.position;
        std::printf("grazing %s (%.2f, %.2f, %.2f): %d px, max rel error %.3g\n",
                    light.type == LightType::Point  ? "point at"
                    : light.type == LightType::Spot ? "spot at"
                                                    : "directional",
                    p.x, p.y, p.z, checked, maxErr);
        EXPECT_GE(checked, 100);
        EXPECT_LT(maxErr, 0.01f);
    }
}

// ---------------------------------------------------------------------------------------------
// Shadows: an off-centre occluder quad between the light and the plane
// ---------------------------------------------------------------------------------------------

/** Where the segment from plane point p toward the light crosses the occluder's plane y = h. */
struct OccluderHit {
    bool crosses = false;
    float insideMargin = 0.0f;  // > 0 inside the quad by that much, < 0 outside by that much
};

OccluderHit traceOccluder(const Light& light, glm::vec3 p, float h, glm::vec2 lo, glm::vec2 hi) {
    glm::vec3 toLight =
        light.type == LightType::Directional ? -light.direction : light.position - p;
    OccluderHit hit;
    if (toLight.y <= 0.0f) return hit;
    float t = h / toLight.y;
    if (light.type != LightType::Directional && t >= 1.0f) return hit;
    glm::vec3 q = p + t * toLight;
    hit.crosses = true;
    float dx = std::min(q.x - lo.x, hi.x - q.x), dz = std::min(q.z - lo.y, hi.y - q.z);
    hit.insideMargin = std::min(dx, dz);
    if (dx < 0.0f && dz < 0.0f) hit.insideMargin = -std::sqrt(dx * dx + dz * dz);
    return hit;
}

class GpuShadowTest : public GpuPassesTest {
protected:
    void runOccluder(const Light& light, const char* label) {
        const float h = 1.0f;
        const glm::vec2 lo(0.1f, -0.1f), hi(0.5f, 0.3f);
        Scene s = planeScene();
        s.materials.push_back(diffuse(glm::vec3(0.5f)));
        addHorizontalQuad(s, h, lo, hi, 1.0f, 1);
        s.lights.push_back(light);
        // Looks at the shadow from the side so the occluder never hides it
        Frame f = render(s, lookAt({3.0f, 2.2f, 0.3f}, {0.6f, 0.0f, 0.2f}));

        float maxUmbra = 0.0f, maxLitErr = 0.0f;
        int umbra = 0, lit = 0;
        for (uint32_t y = 0; y < f.height; ++y) {
            for (uint32_t x = 0; x < f.width; ++x) {
                if (!onPlane(f, x, y)) continue;
                glm::vec3 p(f.at(f.position, x, y));
                glm::vec3 want = light.type == LightType::Directional
                                     ? light.intensity * -light.direction.y
                                     : pointIrradiance(light, p);
                if (light.type == LightType::Spot) want *= spotFactor(light, p);
                if (want.x <= 1e-6f) continue;
                glm::vec3 got = measuredIrradiance(f, x, y);
                OccluderHit hit = traceOccluder(light, p, h, lo, hi);
                if (hit.crosses && hit.insideMargin > 0.04f) {
                    maxUmbra = std::max(maxUmbra, got.x / want.x);
                    ++umbra;
                } else if (!hit.crosses || hit.insideMargin < -0.04f) {
                    maxLitErr = std::max(maxLitErr, relError(got, want));
                    ++lit;
                }
            }
        }
        std::printf("%s occluder: umbra %d px max ratio %.3g, lit %d px max rel error %.3g\n",
                    label, umbra, maxUmbra, lit, maxLitErr);
        EXPECT_GE(umbra, 16);
        EXPECT_GE(lit, 100);
        EXPECT_LT(maxUmbra, 1e-6f);
        EXPECT_LT(maxLitErr, 0.01f);
    }
};

TEST_F(GpuShadowTest, AlphaMaskedOccluderIsCutOut) {
    // Coverage 0.2 below the cutoff 0.5: invisible to the camera and to the light
    Scene s = planeScene();
    Material mask = diffuse(glm::vec3(0.5f));
    mask.baseColorFactor.a = 0.2f;
    mask.alphaMode = AlphaMode::Mask;
    s.materials.push_back(mask);
    addHorizontalQuad(s, 1.0f, glm::vec2(-0.5f), glm::vec2(0.5f), 1.0f, 1);
    Light light = pointLight({0.0f, 2.0f, 0.0f}, glm::vec3(4.0f));
    s.lights.push_back(light);
    Frame f = render(s, topCamera());
    float maxErr = 0.0f;
    for (uint32_t y = 0; y < f.height; ++y) {
        for (uint32_t x = 0; x < f.width; ++x) {
            ASSERT_TRUE(onPlane(f, x, y));
            glm::vec3 p(f.at(f.position, x, y));
            maxErr =
                std::max(maxErr, relError(measuredIrradiance(f, x, y), pointIrradiance(light, p)));
        }
    }
    std::printf("alpha-masked occluder: max rel error %.3g\n", maxErr);
    EXPECT_LT(maxErr, 0.01f);
}

TEST_F(GpuShadowTest, PointLightCubeMap) {
    runOccluder(pointLight({0.05f, 2.0f, 0.0f}, {8.0f, 8.0f, 8.0f}), "point");
}

TEST_F(GpuShadowTest, SpotLight2DMap) {
    Light l;
    l.type = LightType::Spot;
    l.position = {0.1f, 2.0f, 0.1f};
    l.direction = glm::normalize(glm::vec3(0.3f, -1.0f, 0.0f));
    l.intensity = glm::vec3(8.0f);
    l.color = l.intensity;
    l.innerConeRad = 0.5f;
    l.outerConeRad = 0.7f;
    runOccluder(l, "spot");
}

TEST_F(GpuShadowTest, DirectionalLightOrthoMap) {
    Light l;
    l.type = LightType::Directional;
    l.direction = glm::normalize(glm::vec3(-0.2f, -1.0f, 0.1f));
    l.intensity = glm::vec3(3.0f);
    l.color = l.intensity;
    runOccluder(l, "directional");
}

TEST_F(GpuShadowTest, WideSpotUsesCubeMap) {
    Light l;
    l.type = LightType::Spot;
    l.position = {0.05f, 2.0f, 0.0f};
    l.direction = glm::vec3(0.0f, -1.0f, 0.0f);
    l.intensity = glm::vec3(8.0f);
    l.color = l.intensity;
    l.innerConeRad = 1.0f;
    l.outerConeRad = 1.5f;  // > 85 deg
    runOccluder(l, "wide spot");
}

// ---------------------------------------------------------------------------------------------
// Cornell box: shadowed direct light against a CPU reference with exact (ray-cast) visibility
// ---------------------------------------------------------------------------------------------

/** Moller-Trumbore: does the open segment o + t d, t in (tMin, tMax), hit triangle t? */
bool segmentHits(const Scene& s, glm::dvec3 o, glm::dvec3 d, double tMin, double tMax) {
    for (size_t t = 0; t < s.triangleCount(); ++t) {
        glm::dvec3 p0(s.vertices[s.indices[3 * t]].position);
        glm::dvec3 e1 = glm::dvec3(s.vertices[s.indices[3 * t + 1]].position) - p0;
        glm::dvec3 e2 = glm::dvec3(s.vertices[s.indices[3 * t + 2]].position) - p0;
        glm::dvec3 pv = glm::cross(d, e2);
        double det = glm::dot(e1, pv);
        if (std::abs(det) < 1e-14) continue;
        glm::dvec3 tv = o - p0;
        double u = glm::dot(tv, pv) / det;
        if (u < 0.0 || u > 1.0) continue;
        glm::dvec3 qv = glm::cross(tv, e1);
        double v = glm::dot(d, qv) / det;
        if (v < 0.0 || u + v > 1.0) continue;
        double hit = glm::dot(e2, qv) / det;
        if (hit > tMin && hit < tMax) return true;
    }
    return false;
}

/** CPU version of lights.glsl: E_perp and wi toward the light. */
glm::vec3 passLightIrradiance(const PassLight& l, glm::vec3 x, glm::vec3& wi, float& dist) {
    uint32_t type = uint32_t(l.positionType.w);
    if (type == kPassLightDirectional) {
        wi = -glm::vec3(l.direction);
        dist = 1e30f;
        return glm::vec3(l.intensity);
    }
    glm::vec3 d = glm::vec3(l.positionType) - x;
    dist = glm::length(d);
    wi = d / dist;
    glm::vec3 e = glm::vec3(l.intensity) / (dist * dist);
    if (type == kPassLightSpot) {
        float cd = glm::dot(glm::vec3(l.direction), -wi);
        float t = std::clamp((cd - l.cone.y) / (l.cone.x - l.cone.y), 0.0f, 1.0f);
        e *= t * t;
    } else if (type == kPassLightEmitterSample) {
        float c = glm::dot(glm::vec3(l.direction), -wi);
        c = l.direction.w > 0.5f ? std::abs(c) : std::max(c, 0.0f);
        e = glm::vec3(l.intensity) * (c / (dist * dist + l.intensity.w));
    }
    return e;
}

/**
 * Visibility of light l from x by ray casting, or -1 when it is not the same at x and at 8
 * points `radius` away in the tangent plane (penumbra, contact and silhouette zones).
 */
int robustVisibility(const Scene& s, const PassLight& l, glm::vec3 x, glm::vec3 n, float radius) {
    glm::vec3 t = glm::normalize(
        glm::cross(n, std::abs(n.y) < 0.9f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0)));
    glm::vec3 b = glm::cross(n, t);
    int result = -2;
    for (int i = -1; i < 8; ++i) {
        float a = float(i) * 0.785398f;
        glm::vec3 p = i < 0 ? x : x + radius * (std::cos(a) * t + std::sin(a) * b);
        glm::vec3 wi(0.0f);
        float dist = 0.0f;
        passLightIrradiance(l, p, wi, dist);
        glm::dvec3 o = glm::dvec3(p) + 1e-5 * glm::dvec3(n);
        bool visible = !segmentHits(s, o, glm::dvec3(wi), 1e-5, double(dist) - 1e-3);
        if (result == -2) result = visible ? 1 : 0;
        if (result != (visible ? 1 : 0)) return -1;
    }
    return result;
}

/** Direct light against ray-cast visibility on the pixels where every light is robust. */
struct VisibilityStats {
    int checked = 0;      // robust pixels
    int withShadow = 0;   // of those, pixels with at least one occluded light
    int tooDark = 0;      // > 1% below the reference (acne, over-wide shadows)
    int tooBright = 0;    // > 1% above the reference (leaks, peter-panning)
    float maxErr = 0.0f;  // max relative error (1 where the reference is 0 and got > 0)
};

VisibilityStats compareWithRayCast(const Frame& f, const Scene& scene) {
    VisibilityStats st;
    for (uint32_t y = 0; y < f.height; ++y) {
        for (uint32_t x = 0; x < f.width; ++x) {
            glm::vec4 pos = f.at(f.position, x, y);
            if (pos.w <= 0.0f) continue;
            glm::vec3 p(pos), n(f.at(f.normal, x, y)), albedo(f.at(f.albedo, x, y));
            glm::vec3 want(0.0f);
            bool robust = true, anyShadow = false;
            for (const PassLight& l : f.lights) {
                glm::vec3 wi(0.0f);
                float dist = 0.0f;
                glm::vec3 ePerp = passLightIrradiance(l, p, wi, dist);
                float cosTheta = glm::dot(n, wi);
                glm::vec3 e = ePerp * cosTheta;
                if (cosTheta <= 0.0f || e.x + e.y + e.z <= 0.0f) continue;
                // Shadow edges may move by the PCF footprint (r + 0.5 texels) and the normal
                // offset (normalOffset * (r + 1) texels) across the light ray: classify only
                // beyond that (the direct pass uses the surface settings)
                const glm::vec4& b = l.surfaceBias;
                float texel = l.shadow.w > 0.5f ? l.shadow.z : l.shadow.z * dist;
                float reach = b.w + 0.5f + b.z * (b.w + 1.0f) + 0.5f;
                float radius = reach * texel / std::max(cosTheta, 0.2f) + 0.002f;
                int v = robustVisibility(scene, l, p, n, radius);
                if (v < 0) {
                    robust = false;
                    break;
                }
                anyShadow = anyShadow || v == 0;
                want += albedo / kPi * e * float(v);
            }
            if (!robust) continue;
            glm::vec3 got(f.at(f.direct, x, y));
            float err = want.x + want.y + want.z > 0.0f
                            ? relError(got, want)
                            : (got.x + got.y + got.z > 0.0f ? 1.0f : 0.0f);
            if (err > 0.01f) {
                (got.x + got.y + got.z < want.x + want.y + want.z ? st.tooDark : st.tooBright)++;
                if (std::getenv("GILAB_DEBUG_PASSES")) {
                    std::printf(
                        "  px %u,%u p (%.4f %.4f %.4f) n (%.2f %.2f %.2f) got %.5g "
                        "want %.5g\n",
                        x, y, p.x, p.y, p.z, n.x, n.y, n.z, got.x, want.x);
                }
            }
            st.maxErr = std::max(st.maxErr, err);
            ++st.checked;
            st.withShadow += anyShadow ? 1 : 0;
        }
    }
    return st;
}

Scene cornellWithPunctualLights() {
    CornellBoxParams params;
    params.light = false;
    Scene s = makeCornellBox(params);
    Light spot;
    spot.type = LightType::Spot;
    spot.position = {0.278f, 0.54f, 0.28f};
    spot.direction = {0.0f, -1.0f, 0.0f};
    spot.intensity = glm::vec3(1.0f);
    spot.color = spot.intensity;
    spot.innerConeRad = 0.9f;
    spot.outerConeRad = 1.2f;
    s.lights.push_back(spot);
    s.lights.push_back(pointLight({0.12f, 0.45f, 0.15f}, glm::vec3(0.5f)));
    Light sun;  // through the open front, grazing the floor
    sun.type = LightType::Directional;
    sun.direction = glm::normalize(glm::vec3(0.3f, -0.35f, 1.0f));
    sun.intensity = glm::vec3(0.3f);
    sun.color = sun.intensity;
    s.lights.push_back(sun);
    s.computeCaps();
    return s;
}

void expectClean(const VisibilityStats& st, const Frame& f, const char* label) {
    std::printf(
        "cornell %s: %d robust px (%d with a shadowed light), %d too dark, %d too "
        "bright, max rel error %.3g\n",
        label, st.checked, st.withShadow, st.tooDark, st.tooBright, st.maxErr);
    EXPECT_GT(st.checked, int(f.width * f.height / 2));
    EXPECT_GT(st.withShadow, 50);
    EXPECT_LT(st.maxErr, 0.01f);
}

TEST_F(GpuShadowTest, CornellBoxPunctualLightsMatchRayCastVisibility) {
    Scene s = cornellWithPunctualLights();
    Frame f = render(s, s.camera);
    expectClean(compareWithRayCast(f, s), f, "spot + point + directional");
}

// The cascade blend band (shared.shadow_cascade_blend, issue 43 item 4) mixes two cascades'
// visibilities only where they disagree: away from shadow edges both are exact, so the
// ray-cast check holds at the widest band too (a wrong "next" map would break it).
TEST_F(GpuShadowTest, CascadeBlendBandKeepsVisibilityExactAwayFromEdges) {
    Scene s = cornellWithPunctualLights();
    SharedPassSettings settings;
    settings.shadow.cascadeBlend = 0.5f;
    Frame f = render(s, s.camera, settings);
    expectClean(compareWithRayCast(f, s), f, "spot + point + directional, blend 0.5");
}

TEST_F(GpuShadowTest, CornellBoxEmitterSamplesMatchRayCastVisibility) {
    Scene s = makeCornellBox(CornellBoxParams{});
    s.computeCaps();
    SharedPassSettings settings;
    settings.areaLightSamples = 8;
    settings.areaLightAnalytic = false;  // the samples' own sum: their shadow maps are checked
    Frame f = render(s, s.camera, settings);
    ASSERT_EQ(f.lights.size(), 8u);
    expectClean(compareWithRayCast(f, s), f, "8 emitter samples");
}

// ---------------------------------------------------------------------------------------------
// Area light: a square emitter approximated by K emitter samples
// ---------------------------------------------------------------------------------------------

TEST_F(GpuPassesTest, AreaLightConvergesToFormFactor) {
    const float h = 1.0f, half = 0.25f;
    const glm::vec3 le(5.0f, 4.0f, 3.0f);
    Scene s = planeScene();
    Material e = diffuse(glm::vec3(0.0f));
    e.emissiveFactor = le;
    s.materials.push_back(e);
    addHorizontalQuad(s, h, glm::vec2(-half), glm::vec2(half), -1.0f, 1);
    const Camera cam = lookAt({1.5f, 0.6f, 0.0f}, {0.0f, 0.0f, 0.0f});

    // Samples alone: a quadrature that converges with K. With the analytic option (default) the
    // unoccluded irradiance is Lambert's polygon formula, exact for every K.
    for (bool analytic : {false, true}) {
        float errK64 = 0.0f;
        for (uint32_t k : {4u, 16u, 64u}) {
            SharedPassSettings settings;
            settings.areaLightSamples = k;
            settings.areaLightAnalytic = analytic;
            Frame f = render(s, cam, settings);
            float maxErr = 0.0f;
            int checked = 0;
            for (uint32_t y = 0; y < f.height; ++y) {
                for (uint32_t x = 0; x < f.width; ++x) {
                    if (!onPlane(f, x, y)) continue;
                    glm::vec3 p(f.at(f.position, x, y));
                    if (std::abs(p.x) > 0.2f || std::abs(p.z) > 0.2f) continue;
                    double ff = rectangleFormFactor(p, glm::vec2(-half), glm::vec2(half), h);
                    glm::vec3 want = le * float(M_PI * ff);
                    maxErr = std::max(maxErr, relError(measuredIrradiance(f, x, y), want));
                    ++checked;
                }
            }
            std::printf("area light K = %u%s: %d px near the centre, max relative error %.3g\n", k,
                        analytic ? " (analytic)" : "", checked, maxErr);
            EXPECT_GE(checked, 16);
            if (analytic) {
                EXPECT_LT(maxErr, 1e-4f) << "K = " << k;
            }
            if (k == 64) errK64 = maxErr;
        }
        EXPECT_LT(errK64, 0.03f);
    }

    // The emitter seen from below shows exactly Le
    Frame below = render(s, lookAt({0.0f, 0.2f, 0.0f}, {0.0f, 1.0f, 0.0f}, {0, 0, -1}));
    int emitterPixels = 0;
    for (uint32_t y = 0; y < below.height; ++y) {
        for (uint32_t x = 0; x < below.width; ++x) {
            float tri = below.at(below.material, x, y).w;
            if (tri != 3.0f && tri != 4.0f) continue;  // the emitter's two triangles
            EXPECT_EQ(glm::vec3(below.at(below.emission, x, y)), le);
            ++emitterPixels;
        }
    }
    EXPECT_GT(emitterPixels, 100);
}

// Horizon clipping (issue 43: the test above never crosses a receiver's plane): an emitter
// standing through the floor, x = 0.5, y in [-0.25, 0.5], facing -x. Floor points near the centre
// see only its part above y = 0; Lambert's formula over the whole quad counts the part below the
// horizon too (the shader clips each triangle to x's tangent plane). Reference: the irradiance of
// the clipped rectangle by a 400 x 400 midpoint rule.
TEST_F(GpuPassesTest, AreaLightAcrossTheHorizonIsClipped) {
    const float lo = -0.25f, hi = 0.5f, wall = 0.5f, halfZ = 0.25f;
    const glm::vec3 le(2.0f, 3.0f, 4.0f);
    Scene s = planeScene();
    Material e = diffuse(glm::vec3(0.0f));
    e.emissiveFactor = le;
    s.materials.push_back(e);
    appendQuad(s, {wall, lo, -halfZ}, {wall, lo, halfZ}, {wall, hi, halfZ}, {wall, hi, -halfZ},
               {-1.0f, 0.0f, 0.0f}, 1);
    const Camera cam = lookAt({-1.5f, 0.6f, 0.0f}, {0.0f, 0.0f, 0.0f});
    // E / Le = integral over the emitter above y = 0 of cos(receiver) cos(emitter) / r^2 dA.
    auto clippedIntegral = [&](const glm::vec3& p) {
        const int n = 400;
        const double dy = double(hi) / n, dz = 2.0 * double(halfZ) / n;
        double sum = 0.0;
        for (int i = 0; i < n; ++i)
            for (int j = 0; j < n; ++j) {
                const glm::dvec3 q(wall, (i + 0.5) * dy, -halfZ + (j + 0.5) * dz);
                const glm::dvec3 d = q - glm::dvec3(p);
                const double r2 = glm::dot(d, d);
                sum += (d.y / std::sqrt(r2)) * (d.x / std::sqrt(r2)) / r2 * dy * dz;
            }
        return sum;
    };
    SharedPassSettings settings;
    settings.areaLightSamples = 16;
    settings.areaLightAnalytic = true;
    Frame f = render(s, cam, settings);
    float maxErr = 0.0f;
    int checked = 0;
    for (uint32_t y = 0; y < f.height; y += 3) {
        for (uint32_t x = 0; x < f.width; x += 3) {
            if (!onPlane(f, x, y)) continue;
            const glm::vec3 p(f.at(f.position, x, y));
            if (std::abs(p.x) > 0.2f || std::abs(p.z) > 0.2f) continue;
            const glm::vec3 want = le * float(clippedIntegral(p));
            maxErr = std::max(maxErr, relError(measuredIrradiance(f, x, y), want));
            ++checked;
        }
    }
    std::printf("emitter across the horizon: %d px near the centre, max relative error %.3g\n",
                checked, maxErr);
    EXPECT_GE(checked, 8);
    EXPECT_LT(maxErr, 2e-3f);
}

TEST(CpuEmitterSamples, ConservePowerAndStratify) {
    Scene s = planeScene();
    Material e = diffuse(glm::vec3(0.0f));
    e.emissiveFactor = {2.0f, 2.0f, 2.0f};
    s.materials.push_back(e);
    addHorizontalQuad(s, 1.0f, glm::vec2(-0.5f), glm::vec2(0.5f), -1.0f, 1);  // area 1
    addHorizontalQuad(s, 1.5f, glm::vec2(0.0f), glm::vec2(0.1f), -1.0f, 1);   // area 0.01
    s.computeCaps();
    EXPECT_EQ(countEmitterTriangles(s), 4u);
    for (uint32_t k : {1u, 7u, 64u, 1000u}) {
        std::vector<EmitterSample> samples = buildEmitterSamples(s, k);
        ASSERT_EQ(samples.size(), k);
        glm::vec3 power(0.0f);
        for (const EmitterSample& sample : samples) {
            power += sample.intensity;  // Le * A per sample
            EXPECT_NEAR(sample.normal.y, -1.0f, 1e-6f);
        }
        EXPECT_NEAR(power.x, 2.0f * 1.01f, 1e-4f) << k;  // total Le * area
    }
    EXPECT_TRUE(buildEmitterSamples(s, 0).empty());
}

// ---------------------------------------------------------------------------------------------
// Glossy BRDF
// ---------------------------------------------------------------------------------------------

TEST_F(GpuPassesTest, GlossyMatchesCpuGltfBrdf) {
    struct Case {
        glm::vec3 base;
        float metallic, roughness;
    };
    for (const Case& c :
         {Case{{0.8f, 0.6f, 0.3f}, 0.0f, 0.5f}, Case{{0.9f, 0.7f, 0.4f}, 1.0f, 0.3f},
          Case{{0.2f, 0.5f, 0.9f}, 0.5f, 0.15f}}) {
        Scene s = planeScene();
        s.materials[0].baseColorFactor = glm::vec4(c.base, 1.0f);
        s.materials[0].metallic = c.metallic;
        s.materials[0].roughness = c.roughness;
        Light light = pointLight({0.4f, 1.2f, 0.3f}, {6.0f, 5.0f, 4.0f});
        s.lights.push_back(light);
        const Camera cam = lookAt({-1.0f, 1.5f, -0.5f}, {0.2f, 0.0f, 0.1f});
        Frame f = render(s, cam);
        float maxErr = 0.0f;
        int checked = 0;
        for (uint32_t y = 0; y < f.height; ++y) {
            for (uint32_t x = 0; x < f.width; ++x) {
                if (!onPlane(f, x, y)) continue;
                glm::vec3 p(f.at(f.position, x, y));
                glm::vec3 n(0, 1, 0);
                glm::vec3 l = glm::normalize(light.position - p);
                glm::vec3 v = glm::normalize(cam.position - p);
                glm::vec3 want =
                    gltfBrdf(n, l, v, c.base, c.metallic, c.roughness) * pointIrradiance(light, p);
                maxErr = std::max(maxErr, relError(glm::vec3(f.at(f.direct, x, y)), want));
                ++checked;
            }
        }
        std::printf(
            "glossy base (%.1f %.1f %.1f) metallic %.2f roughness %.2f: %d px, max rel "
            "error %.3g\n",
            c.base.x, c.base.y, c.base.z, c.metallic, c.roughness, checked, maxErr);
        EXPECT_GT(checked, 1000);
        EXPECT_LT(maxErr, 1e-3f);
    }
}

// ---------------------------------------------------------------------------------------------
// Skip rules, shadow indices and the shadow-map reuse policy
// ---------------------------------------------------------------------------------------------

bool contains(const std::vector<std::string>& lines, const std::string& prefix) {
    return std::any_of(lines.begin(), lines.end(),
                       [&](const std::string& l) { return l.rfind(prefix, 0) == 0; });
}

TEST_F(GpuPassesTest, SkippedPassesNameWhatTheSceneLacks) {
    Scene point = planeScene();
    point.lights.push_back(pointLight({0, 1, 0}, glm::vec3(1.0f)));
    Frame f = render(point, topCamera());
    EXPECT_TRUE(contains(f.skipped, "shadow.2d:"));
    EXPECT_FALSE(contains(f.skipped, "shadow.cube:"));
    EXPECT_TRUE(contains(f.skipped, "shadow.area_cube:"));
    EXPECT_TRUE(contains(f.skipped, "area_lights:"));
    ASSERT_EQ(f.gpuLights.size(), 1u);
    EXPECT_EQ(f.gpuLights[0].cone.z, 0.0f);

    Scene spot = planeScene();
    Light l;
    l.type = LightType::Spot;
    l.position = {0, 1, 0};
    spot.lights.push_back(pointLight({0, 1, 0}, glm::vec3(1.0f)));
    spot.lights.push_back(l);
    f = render(spot, topCamera());
    EXPECT_FALSE(contains(f.skipped, "shadow.2d:"));
    EXPECT_FALSE(contains(f.skipped, "shadow.cube:"));
    ASSERT_EQ(f.gpuLights.size(), 2u);
    EXPECT_EQ(f.gpuLights[1].cone.z, 1.0f);

    Scene emitter = planeScene();
    Material e = diffuse(glm::vec3(0.0f));
    e.emissiveFactor = glm::vec3(1.0f);
    emitter.materials.push_back(e);
    addHorizontalQuad(emitter, 1.0f, glm::vec2(-0.1f), glm::vec2(0.1f), -1.0f, 1);
    SharedPassSettings settings;
    settings.areaLightSamples = 5;
    f = render(emitter, topCamera(), settings);
    EXPECT_TRUE(contains(f.skipped, "shadow.2d:"));
    EXPECT_TRUE(contains(f.skipped, "shadow.cube:"));
    EXPECT_FALSE(contains(f.skipped, "shadow.area_cube:"));
    EXPECT_FALSE(contains(f.skipped, "area_lights:"));
    EXPECT_EQ(f.lights.size(), 5u);

    settings.areaLightSamples = 0;
    f = render(emitter, topCamera(), settings);
    EXPECT_TRUE(contains(f.skipped, "area_lights:"));
    EXPECT_TRUE(f.lights.empty());
}

TEST_F(GpuPassesTest, ShadowMapsRenderedOnceAndReused) {
    Scene s = planeScene();
    s.lights.push_back(pointLight({0, 1, 0}, glm::vec3(1.0f)));
    s.computeCaps();
    vk::GpuScene gpuScene(*m_ctx, s);
    SharedPasses passes(*m_ctx, gpuScene, 32, 32);
    vk::GpuTimer timer(*m_ctx);
    auto frame = [&]() {
        m_ctx->submitAndWait([&](VkCommandBuffer cmd) {
            timer.reset(cmd);
            passes.record(cmd, topCamera(), &timer);
        });
        std::vector<std::string> names;
        for (const vk::PassTime& t : timer.resolve())
            names.push_back(t.name);
        return names;
    };
    EXPECT_FALSE(passes.shadowsValid());
    EXPECT_EQ(frame(), (std::vector<std::string>{"gbuffer", "shadow_maps", "direct_light"}));
    EXPECT_TRUE(passes.shadowsValid());
    EXPECT_EQ(frame(), (std::vector<std::string>{"gbuffer", "direct_light"}));
    passes.invalidateShadows();
    EXPECT_EQ(frame(), (std::vector<std::string>{"gbuffer", "shadow_maps", "direct_light"}));
}

}  // namespace
}  // namespace gilab

// ---------------------------------------------------------------------------------------------
// View-fitted cascades (core/passes/shadow_cascades.h)
// ---------------------------------------------------------------------------------------------

namespace gilab::cascades_test {

Bounds box(glm::vec3 lo, glm::vec3 hi) {
    Bounds b;
    b.extend(lo);
    b.extend(hi);
    return b;
}

OrthoLightFrame frameFor(const Bounds& b, glm::vec3 dir) {
    OrthoLightFrame f;
    f.direction = glm::normalize(dir);
    f.radius = 1.02f * 0.5f * glm::length(b.extent()) + 1e-4f;
    f.origin = b.center() - f.direction * f.radius;
    return f;
}

}  // namespace gilab::cascades_test

namespace gilab {

TEST(CpuShadowCascades, EachCascadeHoldsItsSliceInsideTheScene) {
    using namespace cascades_test;
    const Bounds scene = box({-15.0f, 0.0f, -7.0f}, {15.0f, 13.0f, 7.0f});  // Sponza-like
    Camera cam;
    cam.position = {-14.0f, 3.0f, 0.0f};
    cam.target = {0.0f, 3.5f, 0.0f};
    cam.vfovRad = glm::radians(55.0f);
    cam.nearZ = 0.05f;
    cam.farZ = 200.0f;
    const float aspect = 16.0f / 9.0f;
    const OrthoLightFrame frame = frameFor(scene, {0.1f, -1.0f, 0.2f});
    CascadeSettings settings;
    settings.count = 4;
    const std::vector<ShadowCascade> c = fitShadowCascades(cam, aspect, scene, frame, settings);
    ASSERT_EQ(c.size(), 4u);
    const float wholeTexel = 2.0f * frame.radius / float(settings.resolution);
    for (size_t i = 0; i < c.size(); ++i) {
        EXPECT_LT(c[i].nearDepth, c[i].farDepth);
        if (i > 0) {
            EXPECT_FLOAT_EQ(c[i].nearDepth, c[i - 1].farDepth);
            EXPECT_GE(c[i].texel, c[i - 1].texel);  // finer near the camera
        }
        EXPECT_LT(c[i].texel, wholeTexel);
        // Points of the slice's frustum inside the scene box project into the cascade, depth
        // inside [0, 1]
        int inside = 0;
        for (int k = 0; k < 2000; ++k) {
            const float u = float(k % 13) / 12.0f, v = float((k / 13) % 11) / 10.0f;
            const float w = float(k / 143) / 13.0f;
            const float z = c[i].nearDepth + w * (c[i].farDepth - c[i].nearDepth);
            const float tanY = std::tan(0.5f * cam.vfovRad);
            const glm::vec3 p = cam.position + cam.forward() * z +
                                cam.right() * ((2.0f * u - 1.0f) * z * tanY * aspect) +
                                cam.trueUp() * ((2.0f * v - 1.0f) * z * tanY);
            if (glm::any(glm::lessThan(p, scene.lo)) || glm::any(glm::greaterThan(p, scene.hi)))
                continue;
            const glm::vec4 clip = c[i].viewProj * glm::vec4(p, 1.0f);
            EXPECT_LE(std::abs(clip.x), 1.0f) << "cascade " << i;
            EXPECT_LE(std::abs(clip.y), 1.0f) << "cascade " << i;
            EXPECT_GE(clip.z, 0.0f);
            EXPECT_LE(clip.z, 1.0f);
            ++inside;
        }
        EXPECT_GT(inside, 100) << "cascade " << i;
    }
    // Linear distance along the light from the entry plane, as the whole-scene map stores it
    const glm::vec3 p(1.0f, 2.0f, 3.0f);
    const float d = glm::dot(p - frame.origin, frame.direction);
    const glm::vec4 clip = c[0].viewProj * glm::vec4(p, 1.0f);
    EXPECT_NEAR(clip.z, 1.0f - d / (2.0f * frame.radius), 1e-5f);
}

// Stable cascades (issue 43): the camera moves by sub-texel steps (a tenth of cascade 0's texel,
// along its right, up and forward axes); every cascade keeps its texel size, and fixed world
// points keep their position inside their texel, so the same texels are rendered and looked up
// and the direct light at a fixed point does not change. Refit exactly (snap off), the
// fractions move with the camera: shadow edges crawl.
TEST(CpuShadowCascades, SubTexelCameraMovesKeepEveryTexelInPlace) {
    using namespace cascades_test;
    const Bounds scene = box({-15.0f, 0.0f, -7.0f}, {15.0f, 13.0f, 7.0f});  // Sponza-like
    Camera cam;
    cam.position = {-11.0f, 2.5f, 1.0f};
    cam.target = {0.0f, 3.5f, -0.5f};
    cam.vfovRad = glm::radians(55.0f);
    cam.nearZ = 0.05f;
    cam.farZ = 200.0f;
    const float aspect = 16.0f / 9.0f;
    const OrthoLightFrame frame = frameFor(scene, {0.1f, -1.0f, 0.2f});
    const glm::vec3 points[] = {
        {-9.0f, 0.0f, 2.0f}, {-5.0f, 1.0f, -3.0f}, {0.0f, 0.0f, 0.0f}, {6.0f, 4.0f, 5.0f}};
    auto texelOf = [](const ShadowCascade& c, const glm::vec3& p, uint32_t res) {
        const glm::vec4 clip = c.viewProj * glm::vec4(p, 1.0f);
        return (0.5f * glm::vec2(clip) + 0.5f) * float(res);
    };
    for (bool snap : {true, false}) {
        CascadeSettings settings;
        settings.count = 4;
        settings.snap = snap;
        const std::vector<ShadowCascade> c0 =
            fitShadowCascades(cam, aspect, scene, frame, settings);
        float worstFraction = 0.0f, worstSize = 0.0f;
        for (int k = 1; k <= 6; ++k) {
            Camera moved = cam;
            const glm::vec3 axis = k % 3 == 0   ? cam.forward()
                                   : k % 3 == 1 ? cam.right()
                                                : cam.trueUp();
            const glm::vec3 step = axis * (0.1f * float(k) * c0[0].texel);
            moved.position += step;
            moved.target += step;
            const std::vector<ShadowCascade> c =
                fitShadowCascades(moved, aspect, scene, frame, settings);
            ASSERT_EQ(c.size(), c0.size());
            for (size_t i = 0; i < c.size(); ++i) {
                worstSize = std::max(worstSize, std::abs(c[i].texel / c0[i].texel - 1.0f));
                for (const glm::vec3& p : points) {
                    const glm::vec2 d = texelOf(c[i], p, settings.resolution) -
                                        texelOf(c0[i], p, settings.resolution);
                    const glm::vec2 off = glm::abs(d - glm::round(d));
                    worstFraction = std::max(worstFraction, std::max(off.x, off.y));
                }
            }
        }
        std::printf(
            "snap %d: sub-texel camera moves shift the texel grid by up to %.4f texel, "
            "texel sizes by %.2g\n",
            int(snap), worstFraction, worstSize);
        if (snap) {
            EXPECT_LT(worstFraction, 2e-3f);
            EXPECT_LT(worstSize, 1e-6f);
        } else {
            EXPECT_GT(worstFraction, 0.02f);  // the defect this guards against
        }
    }
}

TEST(CpuShadowCascades, CameraSeeingNoSceneGetsTheWholeBox) {
    using namespace cascades_test;
    const Bounds scene = box({-1.0f, 0.0f, -1.0f}, {1.0f, 2.0f, 1.0f});
    Camera cam;
    cam.position = {0.0f, 1.0f, 5.0f};
    cam.target = {0.0f, 1.0f, 10.0f};  // looking away
    CascadeSettings settings;
    settings.count = 3;
    // Every one of the box's 8 corners, in x, y and depth, for a vertical and a slanted light
    // (issue 43: two opposite corners under a vertical light were all it checked).
    for (const glm::vec3& dir : {glm::vec3(0.0f, -1.0f, 0.0f), glm::vec3(0.5f, -1.0f, 0.3f)}) {
        const OrthoLightFrame frame = frameFor(scene, dir);
        const std::vector<ShadowCascade> c = fitShadowCascades(cam, 1.0f, scene, frame, settings);
        ASSERT_EQ(c.size(), 3u);
        for (const ShadowCascade& s : c) {
            for (int k = 0; k < 8; ++k) {
                const glm::vec3 corner(k & 1 ? scene.hi.x : scene.lo.x,
                                       k & 2 ? scene.hi.y : scene.lo.y,
                                       k & 4 ? scene.hi.z : scene.lo.z);
                const glm::vec4 clip = s.viewProj * glm::vec4(corner, 1.0f);
                EXPECT_LE(std::abs(clip.x), 1.0f) << "corner " << k;
                EXPECT_LE(std::abs(clip.y), 1.0f) << "corner " << k;
                EXPECT_GE(clip.z, 0.0f) << "corner " << k;
                EXPECT_LE(clip.z, 1.0f) << "corner " << k;
            }
        }
    }
    const OrthoLightFrame frame = frameFor(scene, {0.0f, -1.0f, 0.0f});
    settings.count = 0;
    EXPECT_TRUE(fitShadowCascades(cam, 1.0f, scene, frame, settings).empty());
}

}  // namespace gilab
