// Ray origins that do not depend on where the scene sits (reference/spawn.h, renderer version 5):
// the offsets scale with the triangles and the float spacing at the point, never with |p|. A box
// 5 km from the origin renders as at the origin, region by region; a box on a 5 km ground quad
// keeps its contact shadow; every origin clears the planes near it by their margins.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/image/color.h"
#include "core/scene/camera.h"
#include "core/scene/mesh_builder.h"
#include "core/scene/scene_loader.h"
#include "reference/embree_scene.h"
#include "reference/path_tracer.h"
#include "reference/spawn.h"
#include "reference/texture_lookup.h"
#include "temp_dir.h"

namespace gilab::ref {
namespace {

Material lambert(glm::vec3 albedo) {
    Material m;
    m.baseColorFactor = glm::vec4(albedo, 1.0f);
    return m;
}

uint32_t addMaterial(Scene& s, const Material& m) {
    s.materials.push_back(m);
    return uint32_t(s.materials.size() - 1);
}

/** Renders in world space by default: the offsets then work at the scene's own coordinates
 *  (the camera-relative space would move a translated scene back to the origin). */
Accumulator render(const Scene& scene, uint32_t spp, uint64_t seed, int bounces, PixelFilter filter,
                   RenderSpace space = RenderSpace::World) {
    ReferenceSettings st;
    st.maxBounces = bounces;
    st.seed = seed;
    st.pixelFilter = filter;
    PathTracer tracer(scene, st, space);
    Accumulator acc;
    acc.reset(scene.settings.width, scene.settings.height);
    EXPECT_TRUE(tracer.addSamples(acc, spp));
    return acc;
}

double lum(const Accumulator& a, Layer l, int x, int y) {
    return luminance(float(a.mean(l, x, y, 0)), float(a.mean(l, x, y, 1)),
                     float(a.mean(l, x, y, 2)));
}

/** An upper bound of the luminance's standard error (the channels are correlated). */
double lumError(const Accumulator& a, Layer l, int x, int y) {
    return 0.2126 * a.stdError(l, x, y, 0) + 0.7152 * a.stdError(l, x, y, 1) +
           0.0722 * a.stdError(l, x, y, 2);
}

struct BlockAgreement {
    double meanRatio = 0.0;
    double maxZ = 0.0;
    double rmsZ = 0.0;
    int blocks = 0;
};

/** Two independent renders of the same image, compared per 8 x 8 block of `layer`. */
BlockAgreement compareBlocks(const Accumulator& a, const Accumulator& b, Layer layer, int w,
                             int h) {
    BlockAgreement out;
    double sumA = 0.0, sumB = 0.0, sumZ2 = 0.0;
    for (int by = 0; by < h; by += 8) {
        for (int bx = 0; bx < w; bx += 8) {
            double ma = 0.0, mb = 0.0, va = 0.0, vb = 0.0;
            for (int y = by; y < by + 8; ++y) {
                for (int x = bx; x < bx + 8; ++x) {
                    ma += lum(a, layer, x, y);
                    mb += lum(b, layer, x, y);
                    va += std::pow(lumError(a, layer, x, y), 2);
                    vb += std::pow(lumError(b, layer, x, y), 2);
                }
            }
            sumA += ma;
            sumB += mb;
            const double se = std::sqrt(va + vb);
            if (!(se > 0.0)) continue;
            const double z = (ma - mb) / se;
            out.maxZ = std::max(out.maxZ, std::abs(z));
            sumZ2 += z * z;
            ++out.blocks;
        }
    }
    out.meanRatio = sumA / sumB;
    out.rmsZ = out.blocks > 0 ? std::sqrt(sumZ2 / out.blocks) : 0.0;
    return out;
}

/** The scene moved back by -t exactly (in double, then exact floats): the same float geometry,
 *  lights and camera as `far`, at the origin. The control for a translated scene: what is left
 *  between the two is the renderer's, not the 0.5 mm steps the move put into the scene. */
Scene movedBack(const Scene& far, const glm::dvec3& t) {
    Scene s = far;
    translateScene(s, -t);
    return s;
}

// The procedural Cornell box (0.56 m) moved 5 km out by the scene description's `translate`,
// against the same floats moved back to the origin, both traced in world coordinates;
// different seeds, so the two differ by their noise only. Renderer version 4 stepped every hit back
// by 2^-13 of its coordinates (0.6 m out there, more than the box) and rendered 0.82 x the full
// image, 0.09 x bounce 1.
TEST(CpuReferenceOffsets, BoxFiveKilometresOutAgreesWithTheBoxAtTheOriginPerRegion) {
    test::TempDir dir;
    const std::string file = dir.write("box.json", R"({
        "procedural": {"generator": "cornell_box"},
        "resolution": [64, 64],
        "variants": {"far": {"translate": [5000, 0, 3000]}}
    })");
    const Scene far = loadSceneFile(file, "far");
    const Scene near = movedBack(far, glm::dvec3(5000.0, 0.0, 3000.0));
    ASSERT_NEAR(near.camera.position.x, loadSceneFile(file).camera.position.x, 1e-3f);
    const Accumulator a = render(near, 512, 1, 4, PixelFilter::Box);
    const Accumulator b = render(far, 512, 2, 4, PixelFilter::Box);
    for (Layer layer : {Layer::Full, Layer::Direct, Layer::Bounce1, Layer::Bounce2}) {
        const BlockAgreement g = compareBlocks(b, a, layer, 64, 64);
        std::printf(
            "[ measured ] %s: 5 km / origin mean %.4f, blocks %d, max |z| %.2f, rms z %.2f\n",
            layerName(layer), g.meanRatio, g.blocks, g.maxZ, g.rmsZ);
        EXPECT_GT(g.blocks, 40) << layerName(layer);
        EXPECT_LT(g.maxZ, 4.5) << layerName(layer);
        EXPECT_LT(g.rmsZ, 1.4) << layerName(layer);
        EXPECT_NEAR(g.meanRatio, 1.0, 0.006) << layerName(layer);
    }
}

// In the default camera-relative render space, a scene moved by an exact amount is the same
// scene: the two images are equal bit for bit.
TEST(CpuReferenceOffsets, CameraRelativeSpaceRendersAnExactlyMovedSceneBitForBit) {
    test::TempDir dir;
    const std::string file = dir.write("rooms.json", R"({
        "procedural": {"generator": "two_rooms", "wall_thickness": 0.03125,
                       "door": [0.375, 0.0, 0.625, 0.625]},
        "lights": [{"type": "spot", "position": [0.25, 0.484375, 0.25], "direction": [0, -1, 0],
                    "intensity": 2, "inner_cone_deg": 40, "outer_cone_deg": 50}],
        "camera": {"position": [0.0625, 0.4375, 0.0625], "target": [0.53125, 0.125, 0.25]},
        "resolution": [32, 32],
        "variants": {"far": {"translate": [100000, 0, 60000]}}
    })");
    const Accumulator a =
        render(loadSceneFile(file), 16, 1, 3, PixelFilter::Box, RenderSpace::Camera);
    const Accumulator b =
        render(loadSceneFile(file, "far"), 16, 1, 3, PixelFilter::Box, RenderSpace::Camera);
    ASSERT_EQ(a.sum.size(), b.sum.size());
    size_t differ = 0;
    for (size_t i = 0; i < a.sum.size(); ++i)
        differ += a.sum[i] != b.sum[i];
    EXPECT_EQ(differ, 0u) << "of " << a.sum.size() << " sums";
    // World space, 100 km out (8 mm floats): not the same image
    const Accumulator c = render(loadSceneFile(file, "far"), 16, 1, 3, PixelFilter::Box);
    differ = 0;
    for (size_t i = 0; i < a.sum.size(); ++i)
        differ += a.sum[i] != c.sum[i];
    EXPECT_GT(differ, a.sum.size() / 10);
}

/** A 0.2 m grey box standing on a square ground quad of half-size `half`, lit by a low sun and
 *  seen from above, so that the view stays on a 2 m quad. */
Scene boxOnGround(float half) {
    Scene s;
    s.name = "box_on_ground";
    s.sourcePath = "<test>";
    s.settings.width = s.settings.height = 64;
    const uint32_t grey = addMaterial(s, lambert(glm::vec3(0.5f)));
    appendQuad(s, {-half, 0, -half}, {half, 0, -half}, {half, 0, half}, {-half, 0, half}, {0, 1, 0},
               grey);
    const float b = 0.1f, h = 0.2f;
    appendQuad(s, {-b, h, -b}, {b, h, -b}, {b, h, b}, {-b, h, b}, {0, 1, 0}, grey);     // top
    appendQuad(s, {-b, 0, b}, {b, 0, b}, {b, h, b}, {-b, h, b}, {0, 0, 1}, grey);       // +z
    appendQuad(s, {-b, 0, -b}, {b, 0, -b}, {b, h, -b}, {-b, h, -b}, {0, 0, -1}, grey);  // -z
    appendQuad(s, {b, 0, -b}, {b, 0, b}, {b, h, b}, {b, h, -b}, {1, 0, 0}, grey);       // +x
    appendQuad(s, {-b, 0, -b}, {-b, 0, b}, {-b, h, b}, {-b, h, -b}, {-1, 0, 0}, grey);  // -x
    Light sun;
    sun.type = LightType::Directional;
    sun.direction = glm::normalize(glm::vec3(-1.0f, -0.8f, -0.6f));
    sun.color = glm::vec3(1.0f);
    sun.strength = 3.0f;
    sun.intensity = glm::vec3(3.0f);
    s.lights.push_back(sun);
    s.camera.position = {0.1f, 2.0f, 0.15f};
    s.camera.target = {-0.1f, 0.0f, -0.05f};
    s.camera.up = {0.0f, 1.0f, 0.0f};
    s.camera.vfovRad = glm::radians(30.0f);
    s.computeCaps();
    return s;
}

// The box's shadow on a 5 km ground quad against the same box on a 2 m one (pixel centres, the
// sun's direct light: deterministic per pixel). Version 4 stepped ground hits back by 2^-13 of
// 2500 m (0.3 m) towards the camera, off the ground and out of the shadow.
TEST(CpuReferenceOffsets, SmallBoxKeepsItsContactShadowOnAFiveKilometreGround) {
    const Accumulator small = render(boxOnGround(1.0f), 4, 1, 0, PixelFilter::Center);
    const Accumulator large = render(boxOnGround(2500.0f), 4, 1, 0, PixelFilter::Center);
    int shadowSmall = 0, shadowLarge = 0, differ = 0, lit = 0;
    double peak = 0.0;
    for (int y = 0; y < 64; ++y)
        for (int x = 0; x < 64; ++x)
            peak = std::max(peak, lum(small, Layer::Direct, x, y));
    for (int y = 0; y < 64; ++y) {
        for (int x = 0; x < 64; ++x) {
            const double a = lum(small, Layer::Direct, x, y), b = lum(large, Layer::Direct, x, y);
            shadowSmall += a < 0.05 * peak;
            shadowLarge += b < 0.05 * peak;
            lit += a >= 0.05 * peak;
            differ += std::abs(a - b) > 0.02 * peak;
        }
    }
    std::printf(
        "[ measured ] shadowed pixels: 2 m quad %d, 5 km quad %d; %d of 4096 differ by > 2 %%\n",
        shadowSmall, shadowLarge, differ);
    EXPECT_GT(shadowSmall, 150);  // the box's shadow is in view
    EXPECT_GT(lit, 3000);
    // The view stays on the 2 m quad: its four corner rays meet the ground inside it
    const Scene scene = boxOnGround(1.0f);
    const PrimaryRays rays(scene.camera, 64, 64);
    for (const glm::vec2 corner :
         {glm::vec2(0, 0), glm::vec2(64, 0), glm::vec2(0, 64), glm::vec2(64, 64)}) {
        const Ray r = rays(corner.x, corner.y);
        const glm::vec3 g = r.origin - r.direction * (r.origin.y / r.direction.y);
        EXPECT_LT(std::max(std::abs(g.x), std::abs(g.z)), 1.0f) << corner.x << ", " << corner.y;
    }
    EXPECT_NEAR(shadowLarge, shadowSmall, 0.03 * shadowSmall);
    EXPECT_LE(differ, 40);  // 1 %: pixels on the shadow's edge
}

/** Floor y = 0 and wall x = w meeting at a concave edge, both quads `half` wide around c. */
Scene concaveEdge(glm::vec3 c, float half) {
    Scene s;
    s.name = "edge";
    s.sourcePath = "<test>";
    const uint32_t m = addMaterial(s, lambert(glm::vec3(0.5f)));
    appendQuad(s, c + glm::vec3(-half, 0, -half), c + glm::vec3(0, 0, -half),
               c + glm::vec3(0, 0, half), c + glm::vec3(-half, 0, half), {0, 1, 0}, m);
    appendQuad(s, c + glm::vec3(0, 0, -half), c + glm::vec3(0, 0, half),
               c + glm::vec3(0, half, half), c + glm::vec3(0, half, -half), {-1, 0, 0}, m);
    s.computeCaps();
    return s;
}

/** The floor triangle (0 or 1) whose xz footprint holds p (the one with the nearer centre
 *  when p is on their shared diagonal). */
uint32_t floorTriangle(const EmbreeScene& mesh, const glm::dvec3& p) {
    auto inside = [&](uint32_t prim) {
        const MeshTriangle& t = mesh.triangle(prim);
        const glm::dvec2 a(t.p0.x, t.p0.z), b(t.p1.x, t.p1.z), c(t.p2.x, t.p2.z), q(p.x, p.z);
        auto side = [](glm::dvec2 u, glm::dvec2 v, glm::dvec2 w) {
            return (v.x - u.x) * (w.y - u.y) - (v.y - u.y) * (w.x - u.x);
        };
        const double s0 = side(a, b, q), s1 = side(b, c, q), s2 = side(c, a, q);
        return (s0 >= 0 && s1 >= 0 && s2 >= 0) || (s0 <= 0 && s1 <= 0 && s2 <= 0);
    };
    return inside(0) ? 0u : 1u;
}

// Points on and next to the floor/wall edge: the origin is on the room's side of both planes
// by at least each one's margin (measured in double on the float origin), and it moved by no
// more than the margins and a few float steps, at the origin and 5 km out alike.
TEST(CpuReferenceOffsets, OriginClearsBothPlanesOfAConcaveEdgeByTheirMargins) {
    for (const glm::vec3 centre :
         {glm::vec3(0.3f, 0.0f, 0.2f), glm::vec3(5000.3f, 0.0f, 3000.2f)}) {
        const Scene s = concaveEdge(centre, 1.0f);
        TextureLookup textures(s.textures);
        EmbreeScene mesh(s, textures);
        SpawnOffsets spawn(mesh);
        std::mt19937 rng(7);
        std::uniform_real_distribution<double> u(0.0, 1.0);
        double largestMove = 0.0;
        const double ulp = double(std::nextafter(5000.0f, 1e9f) - 5000.0f);
        const bool far = centre.x > 1000.0f;
        for (int i = 0; i < 2000; ++i) {
            // On the floor, within a few float steps of the edge (x = c.x), or exactly on it
            const double dx = i % 4 == 0 ? 0.0 : -u(rng) * (far ? 8.0 * ulp : 1e-6);
            const glm::dvec3 p(double(centre.x) + dx, 0.0, double(centre.z) + (u(rng) - 0.5));
            // Arriving from inside the room (x < c.x, y > 0)
            const glm::vec3 wo = glm::normalize(glm::vec3(-u(rng), u(rng) + 0.01, u(rng) - 0.5));
            const glm::vec3 o = spawn.origin(p, floorTriangle(mesh, p), wo);
            const glm::dvec3 od(o);
            // The floor triangle under p and the wall triangle holding the edge (2)
            for (const uint32_t prim : {floorTriangle(mesh, p), 2u}) {
                const MeshTriangle& t = mesh.triangle(prim);
                const double margin = intersectionMargin(t, p);
                const glm::dvec3 n = prim < 2 ? glm::dvec3(0, 1, 0) : glm::dvec3(-1, 0, 0);
                const double s = glm::dot(n, od - glm::dvec3(t.p0));
                ASSERT_GE(s, margin)
                    << "point " << i << " triangle " << prim << (far ? " (5 km)" : "");
            }
            // Nothing lies in the room's quarter-space: a ray into it must meet nothing
            for (int k = 0; k < 4; ++k) {
                const glm::vec3 d =
                    glm::normalize(glm::vec3(-u(rng) - 1e-3, u(rng) + 1e-3, 2.0 * u(rng) - 1.0));
                RayHit hit;
                ASSERT_FALSE(mesh.intersect(o, d, 0.0f, 1e30f, hit))
                    << "point " << i << (far ? " (5 km)" : "") << " hit triangle " << hit.prim
                    << " at t = " << hit.t;
            }
            largestMove = std::max(largestMove, glm::length(od - p));
        }
        std::printf("[ measured ] largest move off the edge%s: %.3g m\n", far ? " 5 km out" : "",
                    largestMove);
        // At the origin: micrometres (version 4: 2^-13 of the coordinates plus 256 ulps)
        EXPECT_LT(largestMove, far ? 12.0 * ulp : 2e-5);
    }
}

// Points near the middle of a 5 km ground quad, rays into the upper hemisphere: Embree never
// finds the quad itself again (its test is off by millimetres there; the margin covers it).
TEST(CpuReferenceOffsets, RaysLeavingAFiveKilometreQuadNeverHitIt) {
    Scene s;
    s.name = "ground";
    s.sourcePath = "<test>";
    const uint32_t m = addMaterial(s, lambert(glm::vec3(0.5f)));
    appendQuad(s, {-2500, 0.3f, -2500}, {2500, 0.7f, -2500}, {2500, 0.3f, 2500},
               {-2500, -0.1f, 2500}, {0, 1, 0}, m);  // tilted: every coordinate matters
    s.computeCaps();
    TextureLookup textures(s.textures);
    EmbreeScene mesh(s, textures);
    SpawnOffsets spawn(mesh);
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    int hits = 0, rays = 0;
    for (int i = 0; i < 4000; ++i) {
        const uint32_t prim = uint32_t(i & 1);
        const MeshTriangle& t = mesh.triangle(prim);
        float b1 = u(rng), b2 = u(rng);
        if (b1 + b2 > 1.0f) b1 = 1.0f - b1, b2 = 1.0f - b2;
        b1 *= 0.02f, b2 *= 0.02f;  // near a corner: hundreds of metres to kilometres out
        const glm::dvec3 p =
            glm::dvec3(t.p0) + double(b1) * glm::dvec3(t.e1()) + double(b2) * glm::dvec3(t.e2());
        const glm::vec3 o = spawn.origin(p, prim, t.n);
        for (int k = 0; k < 8; ++k) {
            const float z = u(rng) * 0.999f + 1e-4f, phi = 6.2831853f * u(rng);
            const float r = std::sqrt(1.0f - z * z);
            const glm::vec3 a = glm::normalize(glm::cross(t.n, glm::vec3(0.3f, 0.1f, 0.9f)));
            const glm::vec3 b = glm::cross(t.n, a);
            const glm::vec3 d = z * t.n + r * std::cos(phi) * a + r * std::sin(phi) * b;
            RayHit hit;
            hits += mesh.intersect(o, d, 0.0f, std::numeric_limits<float>::infinity(), hit);
            ++rays;
        }
    }
    EXPECT_EQ(hits, 0) << "of " << rays << " rays";
}

}  // namespace
}  // namespace gilab::ref
