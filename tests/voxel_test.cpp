// Shared voxelization module (core/voxel) against hand-built scenes with known answers.
// Gpu* tests run with validation on and fail on any validation message.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>

#include <glm/glm.hpp>
#include "tests/gpu_test_fixture.h"

#include "core/gpu/gpu_scene.h"
#include "core/scene/mesh_builder.h"
#include "core/scene/procedural_cornell.h"
#include "core/scene/scene.h"
#include "core/scene/scene_loader.h"
#include "core/util/error.h"
#include "core/vk/context.h"
#include "core/vk/timer.h"
#include "core/voxel/voxel_debug_view.h"
#include "core/voxel/voxel_grid.h"
#include "core/voxel/voxel_sat.h"
#include "core/voxel/voxelizer.h"

namespace gilab {
namespace {

using Cell = std::tuple<int, int, int>;

Material diffuse(glm::vec3 albedo, glm::vec3 emission = glm::vec3(0.0f)) {
    Material m;
    m.baseColorFactor = glm::vec4(albedo, 1.0f);
    m.emissiveFactor = emission;
    return m;
}

Scene emptyScene() {
    Scene s;
    s.name = "voxel_test";
    s.sourcePath = "<test>";
    return s;
}

/** Axis-aligned box [lo, hi]^3 with outward faces. */
void addBox(Scene& s, glm::vec3 lo, glm::vec3 hi, uint32_t m) {
    const glm::vec3 a = lo, b = hi;
    appendQuad(s, {a.x, a.y, a.z}, {a.x, b.y, a.z}, {a.x, b.y, b.z}, {a.x, a.y, b.z}, {-1, 0, 0},
               m);
    appendQuad(s, {b.x, a.y, a.z}, {b.x, b.y, a.z}, {b.x, b.y, b.z}, {b.x, a.y, b.z}, {1, 0, 0}, m);
    appendQuad(s, {a.x, a.y, a.z}, {b.x, a.y, a.z}, {b.x, a.y, b.z}, {a.x, a.y, b.z}, {0, -1, 0},
               m);
    appendQuad(s, {a.x, b.y, a.z}, {b.x, b.y, a.z}, {b.x, b.y, b.z}, {a.x, b.y, b.z}, {0, 1, 0}, m);
    appendQuad(s, {a.x, a.y, a.z}, {b.x, a.y, a.z}, {b.x, b.y, a.z}, {a.x, b.y, a.z}, {0, 0, -1},
               m);
    appendQuad(s, {a.x, a.y, b.z}, {b.x, a.y, b.z}, {b.x, b.y, b.z}, {a.x, b.y, b.z}, {0, 0, 1}, m);
}

/** Quad in the plane x = const (facing +-x) or y = const (facing +-y). */
void addQuadX(Scene& s, float x, glm::vec2 lo, glm::vec2 hi, float facing, uint32_t m) {
    appendQuad(s, {x, lo.x, lo.y}, {x, hi.x, lo.y}, {x, hi.x, hi.y}, {x, lo.x, hi.y},
               {facing, 0, 0}, m);
}
void addQuadY(Scene& s, float y, glm::vec2 lo, glm::vec2 hi, float facing, uint32_t m) {
    appendQuad(s, {lo.x, y, lo.y}, {hi.x, y, lo.y}, {hi.x, y, hi.y}, {lo.x, y, hi.y},
               {0, facing, 0}, m);
}

/** CPU reference occupancy: every voxel a triangle overlaps (SAT, Akenine-Moller 2001). */
std::set<Cell> cpuOccupancy(const Scene& s, const VoxelGrid& grid) {
    std::set<Cell> out;
    for (size_t t = 0; t < s.triangleCount(); ++t) {
        glm::vec3 p[3];
        for (int k = 0; k < 3; ++k)
            p[k] = grid.worldToGrid(s.vertices[s.indices[3 * t + k]].position);
        const glm::ivec3 lo =
            glm::max(glm::ivec3(glm::floor(glm::min(p[0], glm::min(p[1], p[2])))) - 1, 0);
        const glm::ivec3 hi =
            glm::min(glm::ivec3(glm::floor(glm::max(p[0], glm::max(p[1], p[2])))) + 1,
                     int(grid.resolution()) - 1);
        for (int z = lo.z; z <= hi.z; ++z)
            for (int y = lo.y; y <= hi.y; ++y)
                for (int x = lo.x; x <= hi.x; ++x)
                    if (triangleBoxOverlap(glm::vec3(x, y, z) + 0.5f, glm::vec3(0.5f), p[0], p[1],
                                           p[2]))
                        out.insert({x, y, z});
    }
    return out;
}

std::set<Cell> gpuOccupancy(const VoxelData& d) {
    std::set<Cell> out;
    const int n = int(d.resolution);
    for (int z = 0; z < n; ++z)
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x)
                if (d.albedoOpacity[d.index({x, y, z})].w > 0.0f) out.insert({x, y, z});
    return out;
}

/** Number of non-finite values over every volume. */
size_t countNonFinite(const VoxelData& d) {
    size_t bad = 0;
    for (const auto* vol : {&d.albedoOpacity, &d.normal, &d.emission})
        for (const glm::vec4& v : *vol)
            for (int k = 0; k < 4; ++k)
                bad += std::isfinite(v[k]) ? 0 : 1;
    return bad;
}

/** Compares occupancies; returns (misses, extras) and prints them. */
std::pair<size_t, size_t> compareOccupancy(const std::set<Cell>& gpu, const std::set<Cell>& cpu,
                                           const char* what) {
    size_t misses = 0, extras = 0;
    for (const Cell& c : cpu)
        misses += gpu.count(c) ? 0 : 1;
    for (const Cell& c : gpu)
        extras += cpu.count(c) ? 0 : 1;
    std::printf("[voxel] %s: cpu %zu cells, gpu %zu cells, misses %zu, extras %zu\n", what,
                cpu.size(), gpu.size(), misses, extras);
    return {misses, extras};
}

class GpuVoxelTest : public test::ValidatedGpuTest {
protected:
    VoxelData voxelize(Scene scene, const VoxelGrid& grid, const VoxelizerOptions& options = {}) {
        scene.computeCaps();
        vk::GpuScene gpuScene(*m_ctx, scene);
        Voxelizer voxelizer(*m_ctx, gpuScene, grid, options);
        voxelizer.run();
        return voxelizer.readVoxels();
    }
};

/** 32^3 grid with 1-unit voxels: world = grid coordinates. */
VoxelGrid unitGrid(uint32_t n = 32) {
    return VoxelGrid::fromCube(glm::vec3(0.0f), 32.0f, n);
}

TEST(CpuVoxelGrid, FitsTheBoundsAndRejectsBadResolutions) {
    Bounds b;
    b.extend({-1.0f, 0.0f, 2.0f});
    b.extend({3.0f, 1.0f, 4.0f});
    VoxelGrid g(b, 64, 0.0f);
    EXPECT_FLOAT_EQ(g.side(), 4.0f);
    EXPECT_FLOAT_EQ(g.voxelSize(), 4.0f / 64.0f);
    EXPECT_EQ(g.voxelOf(b.center()), glm::ivec3(32));
    EXPECT_NEAR(
        glm::length(g.voxelCenter({32, 32, 32}) - b.center() - glm::vec3(g.voxelSize() / 2)), 0.0f,
        1e-6f);
    VoxelGrid m(b, 32);
    EXPECT_FLOAT_EQ(m.side(), 4.0f * (1.0f + VoxelGrid::kDefaultMargin));
    for (uint32_t bad : {0u, 16u, 31u, 513u, 1024u}) {
        try {
            VoxelGrid g2(b, bad);
            FAIL() << "resolution " << bad << " accepted";
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find("resolution"), std::string::npos) << e.what();
        }
    }
}

TEST_F(GpuVoxelTest, BoxVoxelizesToItsExactShell) {
    Scene s = emptyScene();
    const glm::vec3 albedo(0.25f, 0.5f, 0.75f);
    s.materials.push_back(diffuse(albedo));
    const int a = 10, b = 20;  // faces through voxel centres: each lies inside one voxel layer
    addBox(s, glm::vec3(a + 0.5f), glm::vec3(b + 0.5f), 0);
    const VoxelData d = voxelize(s, unitGrid());
    size_t expected = 0, wrong = 0, faceChecked = 0, edgeChecked = 0;
    for (int z = 0; z < 32; ++z) {
        for (int y = 0; y < 32; ++y) {
            for (int x = 0; x < 32; ++x) {
                const glm::ivec3 c(x, y, z);
                const bool inside = glm::all(glm::greaterThanEqual(c, glm::ivec3(a))) &&
                                    glm::all(glm::lessThanEqual(c, glm::ivec3(b)));
                glm::vec3 n(0.0f);  // sum of the face normals meeting at the cell
                for (int k = 0; k < 3; ++k)
                    n[k] = c[k] == a ? -1.0f : (c[k] == b ? 1.0f : 0.0f);
                const bool shell = inside && glm::length(n) > 0.0f;
                const size_t i = d.index(c);
                const bool occupied = d.albedoOpacity[i].w > 0.0f;
                expected += shell ? 1 : 0;
                wrong += occupied != shell ? 1 : 0;
                if (!shell || !occupied) continue;
                EXPECT_NEAR(glm::length(glm::vec3(d.albedoOpacity[i]) - albedo), 0.0f, 1e-3f);
                const glm::vec4 vn = d.normal[i];
                const float faces = std::abs(n.x) + std::abs(n.y) + std::abs(n.z);
                if (faces == 1.0f) {
                    ++faceChecked;
                    EXPECT_NEAR(glm::length(glm::vec3(vn) - n), 0.0f, 2e-3f);
                    EXPECT_NEAR(vn.w, 1.0f, 2e-3f);
                } else {
                    ++edgeChecked;  // edges and corners: the count-weighted average of the faces
                    EXPECT_GT(glm::dot(glm::vec3(vn), glm::normalize(n)), 0.9f) << x << y << z;
                    for (int k = 0; k < 3; ++k)
                        if (n[k] == 0.0f) {
                            EXPECT_NEAR(vn[k], 0.0f, 2e-3f);
                        }
                    EXPECT_LT(vn.w, 0.99f);
                    EXPECT_GT(vn.w, 0.5f);
                }
            }
        }
    }
    std::printf(
        "[voxel] box shell: expected %zu cells, wrong %zu, occupied %zu, faces %zu, "
        "edges/corners %zu\n",
        expected, wrong, d.occupiedCount(), faceChecked, edgeChecked);
    EXPECT_EQ(expected, size_t(11 * 11 * 11 - 9 * 9 * 9));
    EXPECT_EQ(wrong, 0u);
    EXPECT_EQ(d.occupiedCount(), expected);
    EXPECT_EQ(countNonFinite(d), 0u);
}

TEST_F(GpuVoxelTest, OverlappingQuadsAverageByFragmentCount) {
    const glm::vec3 ca(0.2f, 0.9f, 0.1f), cb(0.8f, 0.3f, 0.6f);
    auto quadA = [](Scene& s, uint32_t m) { addQuadY(s, 5.5f, {3.5f, 3.5f}, {9.5f, 9.5f}, 1, m); };
    auto quadB = [](Scene& s, uint32_t m) { addQuadY(s, 5.6f, {6.2f, 4.1f}, {12.7f, 8.3f}, 1, m); };
    Scene sa = emptyScene(), sb = emptyScene(), sab = emptyScene();
    sa.materials.push_back(diffuse(ca));
    sb.materials.push_back(diffuse(cb));
    sab.materials = {diffuse(ca), diffuse(cb)};
    quadA(sa, 0);
    quadB(sb, 0);
    quadA(sab, 0);
    quadB(sab, 1);
    VoxelizerOptions full;
    full.fullPrecision = true;
    const VoxelData da = voxelize(sa, unitGrid(), full), db = voxelize(sb, unitGrid(), full);
    const VoxelData dab = voxelize(sab, unitGrid(), full);
    size_t shared = 0;
    for (size_t i = 0; i < dab.count.size(); ++i) {
        const uint32_t na = da.count[i], nb = db.count[i];
        ASSERT_EQ(dab.count[i], na + nb);
        if (na + nb == 0) continue;
        shared += (na > 0 && nb > 0) ? 1 : 0;
        const glm::vec3 expected = (float(na) * ca + float(nb) * cb) / float(na + nb);
        EXPECT_NEAR(glm::length(glm::vec3(dab.albedoOpacity[i]) - expected), 0.0f, 1e-5f);
    }
    std::printf("[voxel] overlapping quads: %zu voxels with both quads\n", shared);
    EXPECT_GT(shared, 10u);
}

TEST_F(GpuVoxelTest, DenseFanLosesNoUpdates) {
    Scene s = emptyScene();
    s.materials.push_back(diffuse(glm::vec3(0.5f)));
    const glm::vec3 c(5.5f, 6.5f, 7.5f);  // centre of voxel (5, 6, 7)
    const int kTriangles = 200;
    for (int i = 0; i < kTriangles; ++i) {
        const float a0 = 6.2831853f * float(i) / kTriangles,
                    a1 = 6.2831853f * float(i + 1) / kTriangles;
        const glm::vec3 p0 = c + 0.3f * glm::vec3(std::cos(a0), 0.4f * std::sin(a0), std::sin(a0));
        const glm::vec3 p1 = c + 0.3f * glm::vec3(std::cos(a1), 0.4f * std::sin(a1), std::sin(a1));
        const uint32_t base = uint32_t(s.vertices.size());
        const glm::vec3 n = glm::normalize(glm::cross(p0 - c, p1 - c));
        s.vertices.push_back({c, n, {}});
        s.vertices.push_back({p0, n, {}});
        s.vertices.push_back({p1, n, {}});
        s.indices.insert(s.indices.end(), {base, base + 1, base + 2});
        s.triangleMaterials.push_back(0);
    }
    for (bool fixedPoint : {false, true}) {
        VoxelizerOptions o;
        o.forceFixedPoint = fixedPoint;
        const VoxelData d = voxelize(s, unitGrid(), o);
        const size_t i = d.index({5, 6, 7});
        std::printf("[voxel] fan (%s): count %u, occupied %zu\n", fixedPoint ? "fixed" : "float",
                    d.count[i], d.occupiedCount());
        EXPECT_EQ(d.count[i], uint32_t(kTriangles));
        EXPECT_EQ(d.occupiedCount(), 1u);
        EXPECT_NEAR(d.albedoOpacity[i].x, 0.5f, 1e-3f);
    }
}

TEST_F(GpuVoxelTest, OppositeSurfacesGiveZeroNormalAndNoNaN) {
    Scene s = emptyScene();
    s.materials.push_back(diffuse(glm::vec3(0.7f)));
    addQuadX(s, 7.5f, {4.5f, 4.5f}, {12.5f, 12.5f}, 1, 0);
    addQuadX(s, 7.5f, {4.5f, 4.5f}, {12.5f, 12.5f}, -1, 0);
    for (bool fixedPoint : {false, true}) {
        VoxelizerOptions o;
        o.forceFixedPoint = fixedPoint;
        const VoxelData d = voxelize(s, unitGrid(), o);
        EXPECT_EQ(d.occupiedCount(), 9u * 9u);
        size_t nonZero = 0;
        for (size_t i = 0; i < d.normal.size(); ++i)
            if (d.albedoOpacity[i].w > 0.0f && d.normal[i] != glm::vec4(0.0f)) ++nonZero;
        EXPECT_EQ(nonZero, 0u);
        EXPECT_EQ(countNonFinite(d), 0u);
    }
}

TEST_F(GpuVoxelTest, EmissiveQuadHoldsItsRadiance) {
    Scene s = emptyScene();
    const glm::vec3 le(4.0f, 2.5f, 0.75f);
    s.materials.push_back(diffuse(glm::vec3(0.5f), le));
    addQuadY(s, 20.5f, {3.3f, 5.1f}, {17.9f, 11.4f}, -1, 0);
    for (bool fixedPoint : {false, true}) {
        VoxelizerOptions o;
        o.forceFixedPoint = fixedPoint;
        const VoxelData d = voxelize(s, unitGrid(), o);
        size_t covered = 0;
        for (size_t i = 0; i < d.emission.size(); ++i) {
            if (d.albedoOpacity[i].w <= 0.0f) continue;
            ++covered;
            EXPECT_EQ(glm::vec3(d.emission[i]), le) << i;
        }
        EXPECT_GT(covered, 50u);
    }
}

TEST_F(GpuVoxelTest, ResolutionsMatchTheCpuOverlapTest) {
    Scene s = emptyScene();
    s.materials.push_back(diffuse(glm::vec3(0.5f)));
    addBox(s, glm::vec3(10.3f, 9.7f, 11.1f), glm::vec3(20.6f, 17.2f, 22.4f), 0);
    for (uint32_t n : {32u, 64u, 128u}) {
        const VoxelGrid grid = unitGrid(n);
        const VoxelData d = voxelize(s, grid);
        char what[64];
        std::snprintf(what, sizeof(what), "box at %u^3", n);
        const auto [misses, extras] =
            compareOccupancy(gpuOccupancy(d), cpuOccupancy(s, grid), what);
        EXPECT_EQ(misses, 0u);
        EXPECT_EQ(extras, 0u);
        EXPECT_EQ(countNonFinite(d), 0u);
    }
}

TEST_F(GpuVoxelTest, TooLargeForTheDeviceNamesTheResolution) {
    Scene s = emptyScene();
    s.materials.push_back(diffuse(glm::vec3(0.5f)));
    addQuadY(s, 5.5f, {3.5f, 3.5f}, {9.5f, 9.5f}, 1, 0);
    s.computeCaps();
    vk::GpuScene gpuScene(*m_ctx, s);
    const uint64_t plane512 = 512ull * 512 * 512 * 4;
    if (m_ctx->properties().limits.maxStorageBufferRange >= plane512) GTEST_SKIP();
    try {
        Voxelizer v(*m_ctx, gpuScene, unitGrid(512));
        FAIL() << "512^3 accepted";
    } catch (const Error& e) {
        // Named after the techniques' parameter, with the largest grid this device takes
        EXPECT_NE(std::string(e.what()).find("voxel_resolution = 512"), std::string::npos)
            << e.what();
        EXPECT_NE(std::string(e.what()).find("the largest grid here is "), std::string::npos)
            << e.what();
        std::printf("[voxel] 512^3: %s\n", e.what());
    }
}

TEST_F(GpuVoxelTest, AlphaMaskCutoutsAreSkipped) {
    Scene s = emptyScene();
    Material cut = diffuse(glm::vec3(0.9f));
    cut.baseColorFactor.a = 0.3f;
    cut.alphaMode = AlphaMode::Mask;
    cut.alphaCutoff = 0.5f;
    s.materials = {diffuse(glm::vec3(0.2f)), cut};
    addQuadY(s, 5.5f, {3.5f, 3.5f}, {9.5f, 9.5f}, 1, 0);
    addQuadY(s, 5.5f, {3.5f, 3.5f}, {9.5f, 9.5f}, 1, 1);  // same voxels, cut out everywhere
    const VoxelData d = voxelize(s, unitGrid());
    size_t covered = 0;
    for (size_t i = 0; i < d.count.size(); ++i) {
        if (d.count[i] == 0) continue;
        ++covered;
        EXPECT_NEAR(d.albedoOpacity[i].x, 0.2f, 1e-3f);
    }
    EXPECT_GT(covered, 30u);
}

TEST_F(GpuVoxelTest, ThinTriangleNearlyParallelToAnAxisIsNotLost) {
    Scene s = emptyScene();
    s.materials.push_back(diffuse(glm::vec3(0.5f)));
    const glm::vec3 p[3] = {{3.3f, 4.1f, 5.2f}, {28.7f, 6.9f, 5.35f}, {14.2f, 5.0f, 5.61f}};
    const glm::vec3 n = glm::normalize(glm::cross(p[1] - p[0], p[2] - p[0]));
    for (const glm::vec3& q : p)
        s.vertices.push_back({q, n, {}});
    s.indices = {0, 1, 2};
    s.triangleMaterials = {0};
    // A steep sliver too: spans several voxels in depth inside its dominant projection.
    const glm::vec3 r[3] = {{5.2f, 20.1f, 3.3f}, {6.9f, 21.3f, 29.1f}, {5.9f, 24.9f, 16.4f}};
    const glm::vec3 m = glm::normalize(glm::cross(r[1] - r[0], r[2] - r[0]));
    for (const glm::vec3& q : r)
        s.vertices.push_back({q, m, {}});
    s.indices.insert(s.indices.end(), {3, 4, 5});
    s.triangleMaterials.push_back(0);
    const VoxelGrid grid = unitGrid();
    const VoxelData d = voxelize(s, grid);
    const auto [misses, extras] =
        compareOccupancy(gpuOccupancy(d), cpuOccupancy(s, grid), "slivers");
    EXPECT_EQ(misses, 0u);
    EXPECT_EQ(extras, 0u);
}

TEST_F(GpuVoxelTest, DebugViewShowsTheBox) {
    Scene s = emptyScene();
    const glm::vec3 albedo(0.25f, 0.5f, 0.75f);
    s.materials.push_back(diffuse(albedo));
    addBox(s, glm::vec3(10.5f), glm::vec3(20.5f), 0);
    s.computeCaps();
    vk::GpuScene gpuScene(*m_ctx, s);
    Voxelizer voxelizer(*m_ctx, gpuScene, unitGrid());
    VoxelDebugView view(*m_ctx, voxelizer, 64, 48);
    Camera cam;
    cam.position = {15.5f, 15.5f, -20.0f};
    cam.target = {15.5f, 15.5f, 15.5f};
    cam.up = {0.0f, 1.0f, 0.0f};
    cam.vfovRad = 0.5f;
    m_ctx->submitAndWait([&](VkCommandBuffer cmd) {
        voxelizer.record(cmd);
        view.record(cmd, cam, VoxelDebugMode::Albedo);
    });
    const std::vector<float> img = view.image().readbackFloat(*m_ctx);
    const float* centre = &img[(24 * 64 + 32) * 4];
    EXPECT_NEAR(centre[0], albedo.x, 1e-3f);
    EXPECT_NEAR(centre[2], albedo.z, 1e-3f);
    EXPECT_EQ(centre[3], 1.0f);
    EXPECT_EQ(img[3], 0.0f);  // corner pixel misses the box
}

/** Set-up time and memory: Cornell box always at 64^3; GILAB_VOXEL_BENCH=1 adds 128/256 and
 *  Sponza (docs/voxelization.md). */
TEST_F(GpuVoxelTest, SetupTimeAndMemory) {
    const bool bench = std::getenv("GILAB_VOXEL_BENCH") != nullptr;
    std::vector<std::pair<std::string, Scene>> scenes;
    scenes.emplace_back("cornell", makeCornellBox(CornellBoxParams{}));
    const std::string sponza =
        std::string(GILAB_SHARED_SCENES_DIR) + "/dabrovic-sponza/sponza.gltf";
    if (bench && std::filesystem::exists(sponza)) scenes.emplace_back("sponza", loadGltf(sponza));
    for (auto& [name, scene] : scenes) {
        scene.computeCaps();
        vk::GpuScene gpuScene(*m_ctx, scene);
        for (uint32_t n : bench ? std::vector<uint32_t>{64, 128, 256} : std::vector<uint32_t>{64}) {
            Voxelizer voxelizer(*m_ctx, gpuScene, VoxelGrid(scene.caps.bounds, n));
            vk::GpuTimer timer(*m_ctx);
            voxelizer.run(&timer);
            double ms[2] = {0, 0};
            for (const vk::PassTime& t : timer.resolve())
                ms[t.name == "voxelize" ? 0 : 1] += t.gpuMs;
            const double mib = double(m_ctx->memory().totalWithPrefix("voxel/")) / (1 << 20);
            size_t occupied = 0;
            if (n <= 128) {
                const VoxelData d = voxelizer.readVoxels();
                occupied = d.occupiedCount();
                EXPECT_EQ(countNonFinite(d), 0u) << name << " " << n;
                EXPECT_GT(occupied, 0u);
            }
            std::printf(
                "[voxel] %s %zu tris %u^3: voxelize %.1f ms, voxel_resolve %.1f ms, "
                "voxel/ memory %.1f MiB, occupied %zu\n",
                name.c_str(), scene.triangleCount(), n, ms[0], ms[1], mib, occupied);
            EXPECT_GT(mib, 0.0);
        }
    }
}

}  // namespace
}  // namespace gilab
