// The tutorial's technique (docs/tutorial.md, section 5; docs/tutorial/ambient/), compiled into
// this test binary from its folder and checked value by value: one compute pass with one
// descriptor set that reads the G-buffer albedo and writes indirect = ambient x albedo. The same
// folder builds out of the tree against an installed gilab (tests/out_of_tree_test.sh).
#include <algorithm>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <glm/glm.hpp>

#include "tests/gpu_test_fixture.h"

#include "core/passes/gbuffer.h"
#include "core/passes/shared_passes.h"
#include "core/scene/scene_loader.h"
#include "core/technique/frame_harness.h"
#include "core/technique/registry.h"
#include "core/util/error.h"
#include "core/vk/barrier.h"
#include "core/vk/descriptors.h"
#include "core/vk/image.h"
#include "core/vk/pipeline.h"

namespace gilab {

// --- its test ---------------------------------------------------------------------------------

namespace {

using GpuTutorial = test::ValidatedGpuTest;

const Image& layer(const std::vector<ImageLayer>& layers, const std::string& name) {
    for (const ImageLayer& l : layers)
        if (l.name == name) return l.image;
    throw Error("no layer " + name);
}

/** indirect == ambient x albedo and final == emission + direct + indirect, per pixel. */
void expectAmbientTimesAlbedo(const std::vector<ImageLayer>& layers, float ambient) {
    const Image& indirect = layer(layers, "indirect");
    const Image& albedo = layer(layers, "albedo");
    const Image& final = layer(layers, "final");
    const Image& emission = layer(layers, "emission");
    const Image& direct = layer(layers, "direct");
    int lit = 0;
    for (int y = 0; y < indirect.height(); ++y)
        for (int x = 0; x < indirect.width(); ++x)
            for (int c = 0; c < 3; ++c) {
                ASSERT_NEAR(indirect.at(x, y, c), ambient * albedo.at(x, y, c), 1e-5f)
                    << "pixel " << x << "," << y << " channel " << c;
                ASSERT_NEAR(final.at(x, y, c),
                            emission.at(x, y, c) + direct.at(x, y, c) + indirect.at(x, y, c), 1e-5f)
                    << "pixel " << x << "," << y << " channel " << c;
                lit += indirect.at(x, y, c) > 0.0f;
            }
    // Not a vacuous check: over a third of all channel values are lit (the box fills the view).
    EXPECT_GT(lit, indirect.width() * indirect.height());
}

}  // namespace

TEST(CpuTutorial, TechniqueIsRegisteredWithItsParameter) {
    const TechniqueRegistry& r = TechniqueRegistry::instance();
    ASSERT_NE(r.find("ambient"), nullptr);
    EXPECT_FLOAT_EQ(r.defaultParams("ambient").getFloat("ambient"), 0.5f);
}

TEST_F(GpuTutorial, IndirectIsAmbientTimesAlbedo) {
    Scene scene = makeBuiltinDefaultScene();  // the built-in Cornell box, area light
    scene.settings.width = 32;
    scene.settings.height = 32;
    ParamSet params = TechniqueRegistry::instance().defaultParams("ambient");
    FrameHarness h(*m_ctx, scene, "ambient", params, defaultSharedParams());
    ASSERT_TRUE(h.support().supported) << h.support().reason;
    h.setup();
    const FrameTiming frame = h.renderFrame();
    EXPECT_NE(std::find_if(frame.passes.begin(), frame.passes.end(),
                           [](const auto& p) { return p.name == "ambient/ambient"; }),
              frame.passes.end());
    expectAmbientTimesAlbedo(h.readLayers(), 0.5f);

    params.set("ambient", "2.0");  // a per-frame parameter: no new set-up
    h.updateParams(params);
    h.renderFrame();
    expectAmbientTimesAlbedo(h.readLayers(), 2.0f);
}

}  // namespace gilab
