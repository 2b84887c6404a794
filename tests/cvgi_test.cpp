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
#include "core/scene/procedural_cornell.h"
#include "core/scene/scene_loader.h"
#include "core/technique/frame_harness.h"
#include "core/technique/registry.h"
#include "core/util/error.h"
#include "core/vk/context.h"
#include "core/voxel/voxel_compaction.h"
#include "core/voxel/voxelizer.h"
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

// The one-bounce energy on the spot-lit box: with enough rays per face that few lit clusters are
// missed, cvgi's indirect layer carries about the path tracer's one-bounce indirect energy.
TEST_F(GpuCvgi, SpotCornellIndirectIsFiniteAndNearTheOneBounceReference) {
    const Scene scene = spotBox(32);
    FrameHarness h(*m_ctx, scene, "cvgi", cvgiParams({{"rays_per_face", "1024"}}),
                   defaultSharedParams());
    h.setup();
    h.renderFrame();
    const double cvgi = test::indirectLayerSum(h.readLayers());
    ASSERT_GE(cvgi, 0.0);
    const double reference = test::oneBounceReferenceSum(scene, 256);
    ASSERT_GT(reference, 0.0);
    std::printf("spot Cornell 32^2, N = 32, 1024 rays: indirect energy cvgi / reference = %.3f\n",
                cvgi / reference);
    EXPECT_GT(cvgi / reference, 0.5);
    EXPECT_LT(cvgi / reference, 1.3);
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
    p.set("gaussian_kernel", "4");
    EXPECT_THROW(
        {
            try {
                cvgiSettingsFrom(p);
            } catch (const Error& e) {
                EXPECT_NE(std::string(e.what()).find("gaussian_kernel"), std::string::npos);
                throw;
            }
        },
        Error);
}

}  // namespace
}  // namespace gilab
