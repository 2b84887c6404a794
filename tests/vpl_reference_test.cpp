// The same-VPL reference (reference/vpl_reference.h) against closed forms: one VPL over a
// receiver plane (with the VPL on a ceiling, so neither end's own surface may shadow), an
// occluder, the near-VPL clamp, VPLs on the receiving plane, non-finite input, thread-count
// determinism, packets against single rays, and input validation.
#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include "core/scene/mesh_builder.h"
#include "core/util/error.h"
#include "reference/embree_scene.h"
#include "reference/texture_lookup.h"
#include "reference/vpl_reference.h"

namespace gilab::ref {
namespace {

constexpr double kPiD = 3.14159265358979323846;
const glm::vec3 kAlbedo{0.5f, 0.6f, 0.7f};

/** Floor y = 0 facing up and ceiling y = 1 facing down, both [-1, 1]^2; optionally a square
 *  occluder [-0.2, 0.2]^2 at y = 0.5. */
Scene makeRoom(bool occluder) {
    Scene s;
    s.name = "vpl_reference_room";
    s.sourcePath = "<test>";
    Material m;
    m.baseColorFactor = glm::vec4(kAlbedo, 1.0f);
    s.materials.push_back(m);
    auto quad = [&](float y, float half, float facingY) {
        appendQuad(s, {-half, y, -half}, {half, y, -half}, {half, y, half}, {-half, y, half},
                   {0.0f, facingY, 0.0f}, 0);
    };
    quad(0.0f, 1.0f, 1.0f);
    quad(1.0f, 1.0f, -1.0f);
    if (occluder) quad(0.5f, 0.2f, -1.0f);
    return s;
}

/** Holds a Scene with its Embree copy (EmbreeScene keeps references to both). */
struct Room {
    explicit Room(bool occluder)
        : scene(makeRoom(occluder)), textures(scene.textures), embree(scene, textures) {}
    Scene scene;
    TextureLookup textures;
    EmbreeScene embree;
};

/** A size x size G-buffer of floor points at pixel centres over [-0.9, 0.9]^2, normal +y. */
VplReferenceInput floorGBuffer(uint32_t size) {
    VplReferenceInput in;
    in.width = in.height = size;
    for (uint32_t y = 0; y < size; ++y)
        for (uint32_t x = 0; x < size; ++x) {
            const float px = -0.9f + 1.8f * (float(x) + 0.5f) / float(size);
            const float pz = -0.9f + 1.8f * (float(y) + 0.5f) / float(size);
            in.position.emplace_back(px, 0.0f, pz, 1.0f);
            in.normal.emplace_back(0.0f, 1.0f, 0.0f, 0.0f);
            in.albedo.emplace_back(kAlbedo, 1.0f);
        }
    return in;
}

GpuVpl makeVpl(glm::vec3 p, glm::vec3 n, glm::vec3 flux, float bounce = 1.0f) {
    GpuVpl v;
    v.position = glm::vec4(p, 1.0f);
    v.normal = glm::vec4(glm::normalize(n), -1.0f);
    v.flux = glm::vec4(flux, bounce);
    return v;
}

/** albedo / pi x flux cos cos / (pi max(d^2, dMin^2)) in double, for channel c. */
double closedForm(const glm::vec3& p, const glm::vec3& n, const GpuVpl& v, float scale, double dMin,
                  int c) {
    const glm::dvec3 d = glm::dvec3(glm::vec3(v.position)) - glm::dvec3(p);
    const double d2 = glm::dot(d, d);
    const glm::dvec3 l = d / std::sqrt(d2);
    const double cosR = std::max(glm::dot(glm::dvec3(n), l), 0.0);
    const double cosV = std::max(-glm::dot(glm::dvec3(glm::vec3(v.normal)), l), 0.0);
    const double e = double(v.flux[c]) * scale * cosR * cosV / (kPiD * std::max(d2, dMin * dMin));
    return double(kAlbedo[c]) / kPiD * e;
}

void expectNear(double actual, double expected, double rel, const char* what, size_t i, int c) {
    EXPECT_NEAR(actual, expected, rel * std::abs(expected))
        << what << " pixel " << i << " channel " << c;
}

TEST(CpuVplReference, OneVplMatchesClosedFormWithoutOccluder) {
    Room room(false);
    VplReferenceInput in = floorGBuffer(16);
    // A tilted VPL on the ceiling (cos at the VPL varies across the floor), bounce 2
    in.vpls.push_back(makeVpl({0.1f, 1.0f, -0.05f}, {0.3f, -1.0f, 0.2f}, {2.0f, 1.5f, 1.0f}, 2.0f));
    in.bounceScale = {0.25f, 0.75f};
    const VplReferenceResult r = shadeVplsWithShadowRays(room.embree, in);
    ASSERT_EQ(r.exact.size(), in.position.size());
    EXPECT_EQ(r.rays, double(in.position.size()));  // every floor point sees the VPL
    EXPECT_EQ(r.invalidPixels, 0u);
    for (size_t i = 0; i < r.exact.size(); ++i) {
        for (int c = 0; c < 3; ++c) {
            const double expected =
                closedForm(glm::vec3(in.position[i]), {0, 1, 0}, in.vpls[0], 0.75f, 0.0, c);
            ASSERT_GT(expected, 0.0);
            expectNear(r.exact[i][c], expected, 1e-5, "exact", i, c);
            expectNear(r.unshadowed[i][c], expected, 1e-5, "unshadowed", i, c);
        }
        EXPECT_EQ(r.exact[i].w, 1.0f);
    }
}

TEST(CpuVplReference, OccluderShadowsExactOnly) {
    Room room(true);
    VplReferenceInput in = floorGBuffer(16);
    in.vpls.push_back(makeVpl({0.0f, 1.0f, 0.0f}, {0.0f, -1.0f, 0.0f}, {1.0f, 1.0f, 1.0f}));
    const VplReferenceResult r = shadeVplsWithShadowRays(room.embree, in);
    // The occluder's shadow on the floor is |x|, |z| < 0.4 (half-way between floor and VPL)
    int shadowed = 0, lit = 0;
    for (size_t i = 0; i < r.exact.size(); ++i) {
        const glm::vec3 p(in.position[i]);
        const float m = std::max(std::abs(p.x), std::abs(p.z));
        for (int c = 0; c < 3; ++c) {
            const double expected = closedForm(p, {0, 1, 0}, in.vpls[0], 1.0f, 0.0, c);
            expectNear(r.unshadowed[i][c], expected, 1e-5, "unshadowed", i, c);
            if (m < 0.38f) {
                EXPECT_EQ(r.exact[i][c], 0.0f) << "pixel " << i << " should be in shadow";
            } else if (m > 0.42f) {
                EXPECT_EQ(r.exact[i][c], r.unshadowed[i][c]) << "pixel " << i << " should be lit";
            }
        }
        shadowed += m < 0.38f;
        lit += m > 0.42f;
    }
    EXPECT_GE(shadowed, 36);  // both sets are populated
    EXPECT_GE(lit, 100);
}

TEST(CpuVplReference, ClampDistanceAboveDistanceGivesClampedFormula) {
    Room room(false);
    VplReferenceInput in = floorGBuffer(8);
    in.vpls.push_back(makeVpl({0.0f, 1.0f, 0.0f}, {0.0f, -1.0f, 0.0f}, {1.0f, 2.0f, 3.0f}));
    in.clampDistance = 2.0f;  // every floor point is closer than sqrt(1 + 2 0.9^2) < 1.7
    const VplReferenceResult r = shadeVplsWithShadowRays(room.embree, in);
    for (size_t i = 0; i < r.exact.size(); ++i)
        for (int c = 0; c < 3; ++c) {
            const glm::vec3 p(in.position[i]);
            const double clamped = closedForm(p, {0, 1, 0}, in.vpls[0], 1.0f, 2.0, c);
            ASSERT_LT(clamped, closedForm(p, {0, 1, 0}, in.vpls[0], 1.0f, 0.0, c));
            expectNear(r.exact[i][c], clamped, 1e-5, "exact", i, c);
            expectNear(r.unshadowed[i][c], clamped, 1e-5, "unshadowed", i, c);
        }
}

TEST(CpuVplReference, VplOnReceivingPlaneAndNonFiniteInputGiveZeroNotNaN) {
    Room room(false);
    VplReferenceInput in = floorGBuffer(8);
    // Grazing: on the floor facing up; and one exactly at pixel 9's position (d = 0)
    in.vpls.push_back(makeVpl({0.05f, 0.0f, 0.05f}, {0.0f, 1.0f, 0.0f}, {1.0f, 1.0f, 1.0f}));
    in.vpls.push_back(makeVpl(glm::vec3(in.position[9]), {0.0f, 1.0f, 0.0f}, {1.0f, 1.0f, 1.0f}));
    const float nan = std::numeric_limits<float>::quiet_NaN();
    GpuVpl bad = makeVpl({0.0f, 1.0f, 0.0f}, {0.0f, -1.0f, 0.0f}, {1.0f, 1.0f, 1.0f});
    bad.flux.y = nan;
    in.vpls.push_back(bad);
    in.position[3].x = nan;                                   // covered, non-finite
    in.normal[5].z = std::numeric_limits<float>::infinity();  // covered, non-finite
    in.position[7].w = 0.0f;                                  // not covered
    const VplReferenceResult r = shadeVplsWithShadowRays(room.embree, in);
    EXPECT_EQ(r.invalidPixels, 2u);
    EXPECT_EQ(r.invalidVpls, 1u);
    EXPECT_EQ(r.rays, 0.0);
    for (size_t i = 0; i < r.exact.size(); ++i)
        for (int c = 0; c < 4; ++c) {
            EXPECT_EQ(r.exact[i][c], c == 3 ? 1.0f : 0.0f) << "pixel " << i;
            EXPECT_EQ(r.unshadowed[i][c], c == 3 ? 1.0f : 0.0f) << "pixel " << i;
        }
}

/** 30 x 30 floor pixels (partial edge tiles), 64 VPLs on the ceiling, the occluder. */
VplReferenceInput scatteredVpls() {
    VplReferenceInput in = floorGBuffer(30);
    uint32_t state = 12345u;
    auto next = [&] {
        state = state * 1664525u + 1013904223u;
        return float(state >> 8) / float(1u << 24);
    };
    for (int i = 0; i < 64; ++i) {
        const glm::vec3 p(1.8f * next() - 0.9f, 1.0f, 1.8f * next() - 0.9f);
        const glm::vec3 n(next() - 0.5f, -1.0f, next() - 0.5f);
        in.vpls.push_back(makeVpl(p, n, {next(), next(), next()}, i % 2 ? 2.0f : 1.0f));
    }
    in.bounceScale = {0.5f, 0.5f};
    in.clampDistance = 0.3f;
    return in;
}

bool bitEqual(const std::vector<glm::vec4>& a, const std::vector<glm::vec4>& b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(a[0])) == 0;
}

TEST(CpuVplReference, ThreadCountAndPacketsDoNotChangeTheImage) {
    Room room(true);
    VplReferenceInput in = scatteredVpls();
    VplReferenceResult one, two;
    std::vector<double> fractions;
    {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
        one = shadeVplsWithShadowRays(room.embree, in);
    }
    {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
        two = shadeVplsWithShadowRays(room.embree, in, [&](double f) { fractions.push_back(f); });
    }
    EXPECT_TRUE(bitEqual(one.exact, two.exact));
    EXPECT_TRUE(bitEqual(one.unshadowed, two.unshadowed));
    EXPECT_EQ(one.rays, two.rays);
    EXPECT_GT(one.rays, 0.0);
    EXPECT_FALSE(bitEqual(one.exact, one.unshadowed));  // the occluder matters

    // Progress: one call per band of rows, increasing, ending at 1
    ASSERT_FALSE(fractions.empty());
    for (size_t i = 1; i < fractions.size(); ++i)
        EXPECT_GT(fractions[i], fractions[i - 1]);
    EXPECT_EQ(fractions.back(), 1.0);

    in.packets = false;
    const VplReferenceResult single = shadeVplsWithShadowRays(room.embree, in);
    EXPECT_TRUE(bitEqual(single.exact, one.exact));
    EXPECT_EQ(single.rays, one.rays);
}

TEST(CpuVplReference, MismatchedInputSizesThrow) {
    Room room(false);
    VplReferenceInput in = floorGBuffer(4);
    in.albedo.pop_back();
    EXPECT_THROW(shadeVplsWithShadowRays(room.embree, in), Error);
    in = floorGBuffer(4);
    in.height = 5;
    EXPECT_THROW(shadeVplsWithShadowRays(room.embree, in), Error);
    try {
        in = floorGBuffer(4);
        in.normal.resize(3);
        shadeVplsWithShadowRays(room.embree, in);
        FAIL() << "no exception";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("normal"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace gilab::ref
