// Stiff and extreme scenes (scenes/stress/*.json): every registered technique and the path
// tracer must give finite, non-negative output on each, or skip with a reason. New techniques
// are covered automatically through the registry.
#include <cmath>
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

/** Every value a per-frame parameter can be pushed to: its range limits and enum choices. */
std::vector<std::string> extremeValues(const ParamSpec& spec) {
    switch (spec.type) {
        case ParamType::Bool:
            return {"true", "false"};
        case ParamType::Enum:
            return spec.choices;
        case ParamType::Int:
        case ParamType::Float: {
            std::vector<std::string> out;
            for (double v : {spec.minValue, spec.maxValue})
                if (std::isfinite(v))
                    out.push_back(spec.type == ParamType::Int ? std::to_string(int(v))
                                                              : std::to_string(v));
            return out;
        }
    }
    return {};
}

// Extreme parameter values (notes: narrow/wide cones, tiny steps, zero offsets, cutoffs): each
// per-frame parameter of every technique at each limit, one at a time, on the thin wall between
// a lit and a dark room (area light) and next to a point light close to a wall, on the coarsest
// voxel grid.
TEST(GpuStress, PerFrameParametersAtTheirLimitsStayFinite) {
    vk::ContextOptions options;
    options.validation = true;
    vk::Context ctx(options);
    size_t checked = 0;
    for (const char* file : {"thin_wall_window.json", "point_light_near_wall.json"})
        for (const TechniqueInfo* info : TechniqueRegistry::instance().list()) {
            Scene scene = loadSmall(std::string(GILAB_SOURCE_DIR) + "/scenes/stress/" + file);
            scene.settings.width = 16;
            scene.settings.height = 16;
            ParamSet base = TechniqueRegistry::instance().defaultParams(info->id);
            if (base.has("voxel_resolution")) base.set("voxel_resolution", "32");
            if (base.has("topology_cache")) base.set("topology_cache", "off");
            FrameHarness h(ctx, scene, info->id, base, defaultSharedParams());
            if (!h.support().supported) continue;
            h.setup();
            for (const ParamSpec& spec : base.specs()) {
                if (spec.stage != ParamStage::PerFrame) continue;
                for (const std::string& value : extremeValues(spec)) {
                    ParamSet p = base;
                    p.set(spec.name, value);
                    h.updateParams(p);
                    h.renderFrame();
                    const std::string what =
                        info->id + " on " + file + ", " + spec.name + "=" + value;
                    for (const ImageLayer& l : h.readLayers())
                        if (l.name != "normal")
                            expectFiniteNonNegative(l.image, what + " / " + l.name);
                    ++checked;
                }
            }
        }
    EXPECT_GT(checked, 40u);
    std::printf("checked %zu technique/parameter/value combinations\n", checked);
    for (const std::string& m : ctx.validationMessages())
        ADD_FAILURE() << m;
    EXPECT_EQ(ctx.validationErrorCount(), 0u);
}

TEST(GpuStress, EveryTechniqueIsFiniteOrSkipsWithAReason) {
    vk::ContextOptions options;
    options.validation = true;
    vk::Context ctx(options);
    for (const std::string& path : stressScenes()) {
        const Scene scene = loadSmall(path);
        for (const TechniqueInfo* info : TechniqueRegistry::instance().list()) {
            const std::string what = info->id + " on " + scene.name;
            // Defaults, but no voxel grid above 128^3 (topovpl's paper 256^3 skeleton takes tens
            // of seconds per scene on the CPU) and no topology cache outside the test.
            ParamSet params = TechniqueRegistry::instance().defaultParams(info->id);
            if (params.has("voxel_resolution") && params.getInt("voxel_resolution") > 128)
                params.set("voxel_resolution", "128");
            if (params.has("topology_cache")) params.set("topology_cache", "off");
            FrameHarness h(ctx, scene, info->id, params, defaultSharedParams());
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
