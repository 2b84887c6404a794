// Self-gather (issue 9, docs/voxel_cone_tracing.md "Self-gather"): a lit white floor in a box
// whose walls and ceiling are black (scenes/stress/self_gather_floor.json). The floor is a plane
// and cannot see itself, so its true indirect light is exactly 0; every cone tracer must keep the
// floor's gathered light below 5 % of albedo x its own radiance at every voxel resolution.
#include <algorithm>
#include <cstdio>
#include <string>

#include <gtest/gtest.h>

#include "tests/gpu_test_fixture.h"

#include "core/image/image.h"
#include "core/scene/scene_loader.h"
#include "core/technique/frame_harness.h"
#include "core/technique/registry.h"
#include "core/util/error.h"

namespace gilab {
namespace {

const Image& layer(const std::vector<ImageLayer>& layers, const std::string& name) {
    for (const ImageLayer& l : layers)
        if (l.name == name) return l.image;
    throw Error("no layer " + name);
}

struct FloorGather {
    double indirect = 0.0;        // sum over lit floor pixels (luminance-free: rgb sum)
    double albedoRadiance = 0.0;  // sum of albedo x direct (the floor's own radiance)
    int pixels = 0;
    double ratio() const { return albedoRadiance > 0.0 ? indirect / albedoRadiance : 0.0; }
};

FloorGather floorGather(vk::Context& vk, const std::string& technique,
                        std::initializer_list<std::pair<const char*, std::string>> params) {
    Scene scene =
        loadSceneFile(std::string(GILAB_SOURCE_DIR) + "/scenes/stress/self_gather_floor.json");
    scene.settings.width = 64;
    scene.settings.height = 64;
    ParamSet p = TechniqueRegistry::instance().defaultParams(technique);
    for (const auto& [k, v] : params)
        p.set(k, v);
    FrameHarness h(vk, scene, technique, p, defaultSharedParams());
    EXPECT_TRUE(h.support().supported) << h.support().reason;
    h.setup();
    h.renderFrame();
    const auto layers = h.readLayers();
    const Image& indirect = layer(layers, "indirect");
    const Image& direct = layer(layers, "direct");
    const Image& albedo = layer(layers, "albedo");
    FloorGather g;
    double maxDirect = 0.0;
    for (int y = 0; y < direct.height(); ++y)
        for (int x = 0; x < direct.width(); ++x)
            maxDirect = std::max(maxDirect, double(direct.at(x, y, 0)));
    for (int y = 0; y < direct.height(); ++y) {
        for (int x = 0; x < direct.width(); ++x) {
            // The floor is the only non-black surface; keep its clearly lit part.
            if (albedo.at(x, y, 0) < 0.5f || direct.at(x, y, 0) < 0.05 * maxDirect) continue;
            for (int c = 0; c < 3; ++c) {
                g.indirect += indirect.at(x, y, c);
                g.albedoRadiance += double(albedo.at(x, y, c)) * direct.at(x, y, c);
            }
            ++g.pixels;
        }
    }
    return g;
}

using GpuSelfGather = test::ValidatedGpuTest;

TEST_F(GpuSelfGather, LitFloorGathersNoLightFromItself) {
    // vct dense, vct octree, dvs (the octree's vertex-centred bricks have their own lift term).
    const std::pair<const char*, const char*> variants[] = {
        {"vct", "dense"}, {"vct", "octree"}, {"dvs", nullptr}};
    for (const auto& [technique, storage] : variants) {
        for (const char* n : {"32", "64", "128"}) {
            const std::string name =
                std::string(technique) + (storage ? std::string(" ") + storage : "");
            SCOPED_TRACE(name + " " + n + "^3");
            const FloorGather g = storage
                                      ? floorGather(*m_ctx, technique,
                                                    {{"voxel_resolution", n}, {"storage", storage}})
                                      : floorGather(*m_ctx, technique, {{"voxel_resolution", n}});
            std::printf("%s %s^3: floor indirect / (albedo x radiance) = %.4f over %d pixels\n",
                        name.c_str(), n, g.ratio(), g.pixels);
            ASSERT_GT(g.pixels, 200);
            EXPECT_LT(g.ratio(), 0.05);
        }
    }
}

TEST_F(GpuSelfGather, OctreeWithTheDenseLiftGathersALittle) {
    // The octree's extra lift (techniques/vct/svo.md "Lift"): with the dense clearance
    // (octree_lift_extra 0) the floor's own cells reach the lifted samples' footprint.
    const FloorGather g = floorGather(
        *m_ctx, "vct",
        {{"voxel_resolution", "64"}, {"storage", "octree"}, {"octree_lift_extra", "0"}});
    std::printf(
        "vct octree 64^3 octree_lift_extra 0: floor indirect / (albedo x radiance) = %.4f\n",
        g.ratio());
    EXPECT_GT(g.ratio(), 0.005);
    EXPECT_LT(g.ratio(), 0.05);
}

TEST_F(GpuSelfGather, WithoutTheLiftTheFloorGathersItself) {
    // The check above can fail: with the lift off the same march re-gathers the floor's cells,
    // (issue 9 measured 0.55 at 64^3 before the lift and the facing weight; facing alone
    // removes most of a plane's own light: a floor does not shine downward).
    for (const char* lod : {"0", "1"}) {
        const FloorGather g = floorGather(
            *m_ctx, "vct", {{"voxel_resolution", "64"}, {"lift", "0"}, {"lod_offset", lod}});
        std::printf("vct 64^3 lift 0 lod_offset %s: floor indirect / (albedo x radiance) = %.4f\n",
                    lod, g.ratio());
        EXPECT_GT(g.ratio(), 0.04) << "lod_offset " << lod;
    }
}

TEST_F(GpuSelfGather, DvsSecondBounceAddsNoSelfLight) {
    // G1 (the per-voxel gather) marches like the pixel cones: its bounce must not add the
    // floor's own light back (issue 9: +28-33 % before).
    const FloorGather one = floorGather(*m_ctx, "dvs", {{"voxel_resolution", "64"}});
    const FloorGather two =
        floorGather(*m_ctx, "dvs", {{"voxel_resolution", "64"}, {"bounces", "2"}});
    std::printf("dvs 64^3: 1 bounce %.4f, 2 bounces %.4f\n", one.ratio(), two.ratio());
    EXPECT_LT(two.ratio(), 0.05);
    EXPECT_LT(two.ratio(), one.ratio() + 0.02);
}

}  // namespace
}  // namespace gilab
