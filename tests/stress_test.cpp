// Stiff and extreme scenes (scenes/stress/*.json): every registered technique and the path
// tracer must give finite, non-negative output on each, or skip with a reason. New techniques
// are covered automatically through the registry.
#include <filesystem>

#include <gtest/gtest.h>

#include "core/scene/scene_loader.h"
#include "core/technique/frame_harness.h"
#include "core/technique/registry.h"
#include "core/vk/context.h"
#include "reference/path_tracer.h"

namespace gilab {
namespace {

namespace fs = std::filesystem;

std::vector<std::string> stressScenes() {
    std::vector<std::string> out;
    for (const auto& e : fs::directory_iterator(fs::path(GILAB_SOURCE_DIR) / "scenes/stress"))
        if (e.path().extension() == ".json") out.push_back(e.path().string());
    std::sort(out.begin(), out.end());
    out.push_back(std::string(GILAB_SOURCE_DIR) + "/scenes/stress/thin_wall_window.json#closed");
    return out;
}

Scene loadSmall(const std::string& path) {
    Scene scene = loadSceneFile(path);
    scene.settings.width = 32;
    scene.settings.height = 32;
    return scene;
}

void expectFiniteNonNegative(const Image& image, const std::string& what) {
    const FiniteStats s = countNonFinite(image);
    EXPECT_EQ(s.nanPixels, 0u) << what;
    EXPECT_EQ(s.infPixels, 0u) << what;
    EXPECT_EQ(s.negativePixels, 0u) << what;
}

TEST(CpuStress, SceneSetIsPresent) {
    EXPECT_GE(stressScenes().size(), 6u);
}

TEST(GpuStress, EveryTechniqueIsFiniteOrSkipsWithAReason) {
    vk::ContextOptions options;
    options.validation = true;
    vk::Context ctx(options);
    for (const std::string& path : stressScenes()) {
        const Scene scene = loadSmall(path);
        for (const TechniqueInfo* info : TechniqueRegistry::instance().list()) {
            const std::string what = info->id + " on " + scene.name;
            FrameHarness h(ctx, scene, info->id,
                           TechniqueRegistry::instance().defaultParams(info->id),
                           defaultSharedParams());
            if (!h.support().supported) {
                EXPECT_FALSE(h.support().reason.empty()) << what;
                continue;
            }
            h.setup();
            h.renderFrame();
            for (const ImageLayer& l : h.readLayers())
                if (l.name != "normal") expectFiniteNonNegative(l.image, what + " / " + l.name);
        }
    }
    for (const std::string& m : ctx.validationMessages())
        ADD_FAILURE() << m;
    EXPECT_EQ(ctx.validationErrorCount(), 0u);
}

TEST(CpuStress, PathTracerIsFiniteOnEveryStressScene) {
    for (const std::string& path : stressScenes()) {
        const Scene scene = loadSmall(path);
        ref::ReferenceSettings settings;
        settings.maxBounces = 8;
        ref::PathTracer tracer(scene, settings);
        ref::Accumulator acc;
        acc.reset(scene.settings.width, scene.settings.height);
        ASSERT_TRUE(tracer.addSamples(acc, 8));
        EXPECT_EQ(acc.nonFiniteSamples, 0u) << scene.name;
        for (const ImageLayer& l : ref::meanLayers(acc))
            expectFiniteNonNegative(l.image, scene.name + " / " + l.name);
    }
}

// With the window closed, no light can reach the inside of the 2 mm-walled box: the reference
// (watertight ray casting) must be exactly black.
TEST(CpuStress, ClosedThinWalledBoxIsDarkInTheReference) {
    const Scene scene =
        loadSmall(std::string(GILAB_SOURCE_DIR) + "/scenes/stress/thin_wall_window.json#closed");
    ref::ReferenceSettings settings;
    settings.maxBounces = 4;
    ref::PathTracer tracer(scene, settings);
    ref::Accumulator acc;
    acc.reset(scene.settings.width, scene.settings.height);
    tracer.addSamples(acc, 16);
    for (const ImageLayer& l : ref::meanLayers(acc))
        for (float v : l.image.values())
            ASSERT_EQ(v, 0.0f) << l.name;
}

}  // namespace
}  // namespace gilab
