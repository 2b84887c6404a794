// The technique skeleton of docs/tutorial.md, compiled and checked: one compute pass with one
// descriptor set that reads the G-buffer albedo and writes indirect = ambient x albedo.
// It is registered from this file, so it exists only inside this test binary; docs/tutorial.md
// says how to turn it into a real plugin (techniques/<id>/ and one line in CMakeLists.txt).
// Its shader, tests/shaders/tutorial_ambient.comp, is embedded by tests/CMakeLists.txt.
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

// --- the technique (docs/tutorial.md, step 5) ------------------------------------------------

/** A uniform, unoccluded ambient radiance reflected by a Lambertian surface: indirect = rho L_a. */
class TutorialAmbientTechnique final : public Technique {
public:
    static TechniqueInfo describe() {
        TechniqueInfo info;
        info.id = "tutorial_ambient";
        info.description = "tutorial: constant ambient radiance times albedo";
        info.indirectBounces = 1;
        info.params = {floatParam("ambient", 0.5, 0.0, 100.0, "W/(m^2 sr)",
                                  "ambient radiance arriving from every direction")};
        return info;
    }

    void setup(TechniqueContext& ctx) override {
        const VkShaderStageFlags cs = VK_SHADER_STAGE_COMPUTE_BIT;
        // Set 0: binding 0 = G-buffer albedo (read), binding 1 = indirect layer (write).
        m_setLayout = vk::DescriptorSetLayout(ctx.vk,
                                              {{0, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1, cs},
                                               {1, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1, cs}},
                                              ctx.tag("set"));
        m_set = vk::DescriptorSet(ctx.vk, m_setLayout, 0, ctx.tag("set"));
        m_set.writeStorageImage(0, ctx.shared.gbuffer().albedo.view());
        m_boundIndirect = VK_NULL_HANDLE;  // the indirect target is bound in render()
        m_layout = vk::PipelineLayout(ctx.vk, {m_setLayout.handle()}, sizeof(Push), cs);
        m_pipeline = vk::ComputePipeline(ctx.vk, kShader, m_layout);
    }

    void render(TechniqueContext& ctx, VkCommandBuffer cmd, FrameTargets& targets) override {
        if (targets.indirect.view() != m_boundIndirect) {
            m_set.writeStorageImage(1, targets.indirect.view());
            m_boundIndirect = targets.indirect.view();
        }
        const float a = ctx.params.getFloat("ambient");
        const Push push{glm::vec4(a, a, a, 0.0f), glm::uvec4(ctx.width, ctx.height, 0u, 0u)};

        PassScope pass(ctx, cmd, "ambient");  // timed as "tutorial_ambient/ambient"
        m_pipeline.bind(cmd);
        const VkDescriptorSet set = m_set.handle();
        vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, m_layout.handle(), 0, 1, &set,
                                0, nullptr);
        m_layout.push(cmd, push);
        vk::dispatch2D(cmd, ctx.width, ctx.height);  // 8 x 8 groups, as in the shader
        vk::memoryBarrier(cmd);
    }

    /** The run-time name of tests/shaders/tutorial_ambient.comp (relative to shaders/). */
    static constexpr const char* kShader = "../tests/shaders/tutorial_ambient.comp";

private:
    struct Push {  // mirrors `Push` in the shader
        glm::vec4 ambient;
        glm::uvec4 size;
    };
    vk::DescriptorSetLayout m_setLayout;
    vk::DescriptorSet m_set;
    vk::PipelineLayout m_layout;
    vk::ComputePipeline m_pipeline;
    VkImageView m_boundIndirect = VK_NULL_HANDLE;
};
GILAB_REGISTER_TECHNIQUE(TutorialAmbientTechnique)

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
    ASSERT_NE(r.find("tutorial_ambient"), nullptr);
    EXPECT_FLOAT_EQ(r.defaultParams("tutorial_ambient").getFloat("ambient"), 0.5f);
}

TEST_F(GpuTutorial, IndirectIsAmbientTimesAlbedo) {
    Scene scene = makeBuiltinDefaultScene();  // the built-in Cornell box, area light
    scene.settings.width = 32;
    scene.settings.height = 32;
    ParamSet params = TechniqueRegistry::instance().defaultParams("tutorial_ambient");
    FrameHarness h(*m_ctx, scene, "tutorial_ambient", params, defaultSharedParams());
    ASSERT_TRUE(h.support().supported) << h.support().reason;
    h.setup();
    const FrameTiming frame = h.renderFrame();
    EXPECT_NE(std::find_if(frame.passes.begin(), frame.passes.end(),
                           [](const auto& p) { return p.name == "tutorial_ambient/ambient"; }),
              frame.passes.end());
    expectAmbientTimesAlbedo(h.readLayers(), 0.5f);

    params.set("ambient", "2.0");  // a per-frame parameter: no new set-up
    h.updateParams(params);
    h.renderFrame();
    expectAmbientTimesAlbedo(h.readLayers(), 2.0f);
}

}  // namespace gilab
