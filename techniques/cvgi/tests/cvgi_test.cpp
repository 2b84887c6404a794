// `cvgi` on the GPU (issue 12): the shared fragment lists and prefix-sum compaction against the
// dense voxelization, the per-voxel "processed" cache under camera and emitter moves (counted),
// and the indirect energy against the path tracer's one-bounce reference. The CPU set-up
// (clustering, visibility, form factor) is tested in cvgi_setup_test.cpp.
#include <cmath>
#include <cstdio>
#include <map>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "tests/gpu_test_fixture.h"
#include "tests/harness_stats.h"
#include "tests/indirect_energy.h"

#include "core/gpu/gpu_scene.h"
#include "core/scene/animation.h"
#include "core/scene/mesh_builder.h"
#include "core/scene/procedural_cornell.h"
#include "core/scene/scene_loader.h"
#include "core/technique/frame_harness.h"
#include "core/technique/registry.h"
#include "core/util/error.h"
#include "core/vk/context.h"
#include "core/voxel/voxel_compaction.h"
#include "core/voxel/voxelizer.h"
#include "reference/light_power.h"
#include "reference/path_tracer.h"
#include "techniques/cvgi/cvgi_settings.h"

namespace gilab {
namespace {

using GpuCvgi = test::ValidatedGpuTest;

Scene spotBox(int size) {
    Scene scene = loadSceneFile(std::string(GILAB_SOURCE_DIR) + "/scenes/cornell_box.json", "spot");
    scene.settings.width = size;
    scene.settings.height = size;
    return scene;
}

ParamSet cvgiParams(const std::map<std::string, std::string>& values) {
    ParamSet p = TechniqueRegistry::instance().defaultParams("cvgi");
    p.set("voxel_resolution", "32");
    p.set("shadow_map_size", "512");
    for (const auto& [k, v] : values)
        p.set(k, v);
    return p;
}

using test::stat;

// §4.1: every voxel the dense voxelizer covers is in the compacted list, in ascending order, with
// as many fragments in its list as the dense pass counted; the dense map inverts the list.
TEST_F(GpuCvgi, CompactionMatchesTheDenseVoxelization) {
    const Scene scene = makeCornellBox(CornellBoxParams{});
    vk::GpuScene gpuScene(*m_ctx, scene);
    const VoxelGrid grid(scene.caps.bounds, 32);
    VoxelizerOptions options;
    options.fragmentCapacity = 64;  // far too small: run() must grow it and voxelize again
    Voxelizer voxelizer(*m_ctx, gpuScene, grid, options);
    voxelizer.run();
    VoxelFragmentLists& lists = *voxelizer.fragments();
    const uint32_t fragments = lists.written();
    ASSERT_FALSE(lists.overflowed());
    EXPECT_GT(lists.capacity(), 64u);
    EXPECT_THROW(voxelizer.readVoxels(), Error);  // fragment-list mode has no volumes
    Voxelizer denseVoxelizer(*m_ctx, gpuScene, grid);
    denseVoxelizer.run();
    const VoxelData dense = denseVoxelizer.readVoxels();

    VoxelCompaction compaction(*m_ctx, grid, lists.heads());
    m_ctx->submitAndWait([&](VkCommandBuffer cmd) { compaction.recordScan(cmd); });
    const uint32_t occupied = compaction.readOccupied();
    m_ctx->submitAndWait([&](VkCommandBuffer cmd) { compaction.recordFill(cmd, occupied); });
    EXPECT_EQ(occupied, dense.occupiedCount());

    const auto hashed = compaction.hashedPosition().downloadVector<uint32_t>(occupied);
    const auto heads = compaction.fragmentIndex().downloadVector<uint32_t>(occupied);
    const auto index = compaction.voxelIndex().downloadVector<uint32_t>(grid.voxelCount());
    const auto list = lists.readFragments(fragments);
    uint64_t walked = 0;
    for (uint32_t i = 0; i < occupied; ++i) {
        if (i > 0) ASSERT_LT(hashed[i - 1], hashed[i]);
        ASSERT_GT(dense.count[hashed[i]], 0u);
        ASSERT_EQ(index[hashed[i]], i);
        uint32_t n = 0;
        for (uint32_t f = heads[i]; f != kVoxelListEnd && n <= fragments; f = list[f].next)
            ++n;
        EXPECT_EQ(n, dense.count[hashed[i]]) << "voxel " << hashed[i];
        walked += n;
    }
    EXPECT_EQ(walked, fragments);
    size_t empty = 0;
    for (uint32_t v : index)
        empty += v == kVoxelListEnd ? 1 : 0;
    EXPECT_EQ(empty, grid.voxelCount() - occupied);
}

// §4.4 and Fig. 5 (left): the first update gathers every visible voxel; a camera move gathers
// only the voxels not gathered before (moving back gathers none); an emitter move gathers every
// visible voxel again.
TEST_F(GpuCvgi, CameraOnlyMoveGathersOnlyNewlyVisibleVoxels) {
    const Scene scene = spotBox(32);
    FrameHarness h(*m_ctx, scene, "cvgi", cvgiParams({}), defaultSharedParams());
    ASSERT_TRUE(h.support().supported) << h.support().reason;
    h.setup();
    h.renderFrame();
    const double visible0 = stat(h, "visible_voxels");
    EXPECT_GT(visible0, 100.0);
    EXPECT_EQ(stat(h, "gathered_voxels"), visible0);

    // Sideways and closer: part of the view is new.
    SceneFrameState moved = frameState(scene, 0);
    moved.camera.position += glm::vec3(0.15f, 0.05f, 0.4f);
    moved.camera.target += glm::vec3(0.25f, 0.0f, 0.0f);
    h.setFrameState(moved);
    FrameTiming t = h.renderFrame();
    EXPECT_EQ(t.update, UpdateKind::Incremental);
    const double visible1 = stat(h, "visible_voxels"), gathered1 = stat(h, "gathered_voxels");
    std::printf("camera move: %.0f visible, %.0f newly gathered (first view %.0f)\n", visible1,
                gathered1, visible0);
    EXPECT_GT(gathered1, 0.0);
    EXPECT_LT(gathered1, 0.5 * visible1);

    h.setFrameState(frameState(scene, 0));  // back: everything seen was gathered already
    h.renderFrame();
    EXPECT_EQ(stat(h, "visible_voxels"), visible0);
    EXPECT_EQ(stat(h, "gathered_voxels"), 0.0);

    SceneFrameState light = frameState(scene, 0);
    light.lights.at(0).position.x -= 0.1f;
    h.setFrameState(light);
    h.renderFrame();
    EXPECT_EQ(stat(h, "gathered_voxels"), visible0);  // the emitter moved: all invalidated
    for (const ImageLayer& l : h.readLayers()) {
        if (l.name != "final" && l.name != "indirect") continue;
        EXPECT_TRUE(countNonFinite(l.image).allFinite()) << l.name;
        for (float v : l.image.values())
            ASSERT_GE(v, 0.0f) << l.name;
    }
}

// The one-bounce energy on the spot-lit box (issue 28). With enough rays per face that few lit
// clusters are missed, the paper's gather carries about the path tracer's one-bounce indirect
// energy; at its 128 rays it loses a share that grows with N (§4.3 samples each cluster with the
// face's rays). The ray-weighted gather (ours) is near 1 at 128 rays at every N. The old
// dominant-axis neighbour test gave 0.45 of the 1024-ray paper row: the bound below catches it.
struct EnergyCase {
    const char* gather;
    const char* resolution;
    const char* rays;
    double lo, hi;
};

TEST_F(GpuCvgi, SpotCornellIndirectEnergyAgainstTheOneBounceReference) {
    const Scene scene = spotBox(32);
    const double reference = test::oneBounceReferenceSum(scene, 256);
    ASSERT_GT(reference, 0.0);
    const EnergyCase cases[] = {
        // Measured (issue 43, stratum-centre directions): 0.918, 0.462, 1.014, 1.008. The bands
        // are about +-7 % around them (the reference's own noise is below 1 %): the paper's
        // sampling loss at 64^3 reproduced, not a factor 3.5 either way.
        {"paper", "32", "1024", 0.87, 0.98},
        {"paper", "64", "128", 0.43, 0.50},  // the paper's sampling loss, reproduced
        {"ray_weighted", "32", "128", 0.96, 1.05},
        {"ray_weighted", "64", "128", 0.96, 1.05},
    };
    for (const EnergyCase& c : cases) {
        FrameHarness h(*m_ctx, scene, "cvgi",
                       cvgiParams({{"gather", c.gather},
                                   {"voxel_resolution", c.resolution},
                                   {"rays_per_face", c.rays}}),
                       defaultSharedParams());
        h.setup();
        h.renderFrame();
        const double cvgi = test::indirectLayerSum(h.readLayers());
        ASSERT_GE(cvgi, 0.0);
        std::printf(
            "spot Cornell 32^2, gather %s, N = %s, %s rays: cvgi / reference = %.3f "
            "(rays per lit entry %.2f)\n",
            c.gather, c.resolution, c.rays, cvgi / reference, stat(h, "rays_per_lit_entry"));
        EXPECT_GT(cvgi / reference, c.lo) << c.gather << " N " << c.resolution << " " << c.rays;
        EXPECT_LT(cvgi / reference, c.hi) << c.gather << " N " << c.resolution << " " << c.rays;
        EXPECT_EQ(stat(h, "lit_clusters_never_hit_percent"), 0.0);  // a closed box
        EXPECT_GT(stat(h, "rays_seeing_lit_percent"), 5.0);
    }
}

/** A floor, a 45-degree slope and a wall facing the light at a grazing angle, under Sponza's
 *  steep sun (direction (0.1, -1, 0.2)). */
Scene slopeUnderASteepSun() {
    Scene s;
    s.name = "slope_under_a_steep_sun";
    s.sourcePath = "<test>";
    appendLambertianMaterial(s, "stone", glm::vec3(0.6f, 0.5f, 0.4f));
    appendQuad(s, {-1, 0, -1}, {1, 0, -1}, {1, 0, 1}, {-1, 0, 1}, {0, 1, 0}, 0);  // floor
    appendQuad(s, {-0.9f, 0.0f, -0.7f}, {-0.1f, 0.8f, -0.7f}, {-0.1f, 0.8f, 0.7f},
               {-0.9f, 0.0f, 0.7f}, {-1, 1, 0}, 0);  // slope
    appendQuad(s, {0.1f, 0, -1}, {0.1f, 1, -1}, {0.1f, 1, 1}, {0.1f, 0, 1}, {-1, 0, 0}, 0);  // wall
    Light sun;
    sun.type = LightType::Directional;
    sun.name = "sun";
    sun.direction = glm::normalize(glm::vec3(0.1f, -1.0f, 0.2f));
    sun.intensity = glm::vec3(10.0f);
    sun.color = sun.intensity;
    s.lights.push_back(sun);
    s.camera.position = {0.0f, 2.5f, 3.0f};
    s.camera.target = {0.0f, 0.3f, 0.0f};
    s.settings.width = s.settings.height = 32;
    s.computeCaps();
    return s;
}

/** The slope scene with only surface `keep` (0 floor, 1 slope, 2 wall) reflecting light. */
Scene onlySurface(int keep) {
    Scene s = slopeUnderASteepSun();
    const uint32_t black = appendLambertianMaterial(s, "black", glm::vec3(0.0f));
    for (size_t t = 0; t < s.triangleMaterials.size(); ++t)
        if (int(t / 2) != keep) s.triangleMaterials[t] = black;
    s.name += keep == 1 ? " (slope)" : " (wall)";
    return s;
}

// The lit voxels hold the power the light reflects off the surfaces it reaches, traced by Embree
// (reference/light_power.h, `gilab bench light-power`): the control of issue 43. Measured at
// 64^3: slope 1.005, wall 1.096 (each alone reflecting; the wall is lit at 84 deg), the box 1.03
// (and the floor 1.17: its voxels near the slope's foot see past it through the paper's 18 test
// points). Fails with the neighbour test's earlier reading: slope 0.51, wall 0.03 (Sponza's sun
// held 0.51 at 64^3).
TEST_F(GpuCvgi, LitVoxelsHoldTheReflectedPowerEmbreeTraces) {
    for (const Scene& scene : {onlySurface(1), onlySurface(2), spotBox(32)}) {
        const double traced = ref::punctualLightPower(scene, 1u << 18).front().reflectedW;
        FrameHarness h(
            *m_ctx, scene, "cvgi",
            cvgiParams(
                {{"voxel_resolution", "64"}, {"rays_per_face", "16"}, {"shadow_map_size", "2048"}}),
            defaultSharedParams());
        h.setup();
        h.renderFrame();
        const double held = stat(h, "lit_power_w");
        std::printf("%s: lit voxels hold %.4g W, Embree traces %.4g W reflected (%.3f)\n",
                    scene.name.c_str(), held, traced, held / traced);
        EXPECT_NEAR(held / traced, 1.0, 0.12) << scene.name;
    }
}

// Fig. 10's neighbour test removes voxels behind an occupied neighbour toward the light, not the
// walls lit at an angle (their dominant-axis neighbour is the next voxel of the same wall) nor
// the voxels of a slope (issue 43): on the box it keeps every voxel (the dominant-axis reading
// kept 0.48, issue 28's reading 0.96); under the slope, the floor voxels whose upper neighbour is
// the slope (lit through test points that see past its foot) are removed.
TEST_F(GpuCvgi, NeighbourTestKeepsWallsLitAtAnAngle) {
    auto litVoxels = [&](const Scene& scene, const char* test) {
        FrameHarness h(*m_ctx, scene, "cvgi",
                       cvgiParams({{"neighbour_test", test}, {"rays_per_face", "32"}}),
                       defaultSharedParams());
        h.setup();
        h.renderFrame();
        return stat(h, "lit_voxels");
    };
    const Scene box = spotBox(32);
    const double on = litVoxels(box, "true"), off = litVoxels(box, "false");
    std::printf("box: lit voxels with the neighbour test %.0f, without %.0f\n", on, off);
    EXPECT_GT(on, 0.99 * off);
    const Scene slope = slopeUnderASteepSun();
    const double slopeOn = litVoxels(slope, "true"), slopeOff = litVoxels(slope, "false");
    std::printf("slope: lit voxels with the neighbour test %.0f, without %.0f\n", slopeOn,
                slopeOff);
    EXPECT_LT(slopeOn, slopeOff);
    EXPECT_GT(slopeOn, 0.9 * slopeOff);
}

// Issue 28: the paper's Gaussian gives non-lit neighbours weight 0 and renormalises, so a dark
// face takes its lit neighbours' mean, also through a wall; gaussian_visibility (ours, default)
// skips neighbours behind occupied voxels. Two rooms, door closed, seen from the dark room: the
// path tracer has 0 there (docs/shared_passes.md, "Measured": the shared direct light is 0 too).
TEST_F(GpuCvgi, GaussianDoesNotSpreadLightThroughAClosedWall) {
    Scene scene = loadSceneFile(
        std::string(GILAB_SOURCE_DIR) + "/scenes/stress/two_rooms_door.json", "room_b_closed");
    scene.settings.width = 32;
    scene.settings.height = 32;
    auto darkRoomLight = [&](const char* visibility, const char* passes) {
        FrameHarness h(*m_ctx, scene, "cvgi",
                       cvgiParams({{"voxel_resolution", "64"},
                                   {"rays_per_face", "32"},
                                   {"gaussian_passes", passes},
                                   {"gaussian_visibility", visibility}}),
                       defaultSharedParams());
        h.setup();
        h.renderFrame();
        return test::indirectLayerSum(h.readLayers());
    };
    // The control: no filter at all. What room B gets then comes through the gather itself (a
    // 0.02 m wall is about one 64^3 voxel); the filter must add nothing to it.
    const double unfiltered = darkRoomLight("true", "0");
    const double paperFilter = darkRoomLight("false", "2"), ours = darkRoomLight("true", "2");
    std::printf(
        "indirect light in the closed room: unfiltered %.4g, paper filter %.4g, ours %.4g\n",
        unfiltered, paperFilter, ours);
    EXPECT_GT(paperFilter, 2.0 * unfiltered);  // the leak this guards against
    EXPECT_LE(ours, 1.02 * unfiltered + 1e-6 * paperFilter);
}

// Bad input (issue 28): a wide frame asks for a camera distance map wider than the device allows;
// the map is clamped to the limit, said in a note, and the run stays validation-clean.
TEST_F(GpuCvgi, CameraMapIsClampedToTheDeviceLimit) {
    Scene scene = spotBox(8);
    const uint32_t maxSide = m_ctx->properties().limits.maxImageDimension2D;
    scene.settings.width = int(std::min(maxSide, 4096u));
    scene.settings.height = 1;
    const uint32_t side = 8 * maxSide / uint32_t(scene.settings.width);  // 8x the limit wide
    FrameHarness h(*m_ctx, scene, "cvgi",
                   cvgiParams({{"camera_map_size", std::to_string(side)},
                               {"rays_per_face", "8"},
                               {"voxel_resolution", "32"}}),
                   defaultSharedParams());
    h.setup();
    h.renderFrame();
    bool noted = false;
    for (const std::string& n : h.notes())
        noted = noted || n.find("clamped to the device's image limit") != std::string::npos;
    EXPECT_TRUE(noted);
    for (const ImageLayer& l : h.readLayers())
        EXPECT_TRUE(countNonFinite(l.image).allFinite()) << l.name;
}

TEST_F(GpuCvgi, UnsupportedLightsGiveAReason) {
    Scene point =
        loadSceneFile(std::string(GILAB_SOURCE_DIR) + "/scenes/cornell_box.json", "point");
    FrameHarness a(*m_ctx, point, "cvgi", cvgiParams({}), defaultSharedParams());
    EXPECT_FALSE(a.support().supported);
    EXPECT_NE(a.support().reason.find("point"), std::string::npos) << a.support().reason;
    FrameHarness b(*m_ctx, makeCornellBox(CornellBoxParams{}), "cvgi", cvgiParams({}),
                   defaultSharedParams());
    EXPECT_FALSE(b.support().supported);
    EXPECT_NE(b.support().reason.find("emissive"), std::string::npos) << b.support().reason;
}

TEST(CpuCvgiParams, EvenGaussianKernelIsRejectedByName) {
    ParamSet p = TechniqueRegistry::instance().defaultParams("cvgi");
    EXPECT_THROW(  // the declaration's rule (0 or odd), checked when the value is set
        {
            try {
                p.set("gaussian_kernel", "4");
            } catch (const Error& e) {
                EXPECT_NE(std::string(e.what()).find("gaussian_kernel"), std::string::npos);
                throw;
            }
        },
        Error);
}

}  // namespace
}  // namespace gilab
