// ambient: the tutorial's technique (docs/tutorial.md, section 5). A uniform ambient radiance L_a
// reaches every surface point unoccluded and a Lambertian surface reflects it:
//     indirect = albedo * L_a
// One compute pass with one descriptor set. This folder is a whole technique: it builds inside
// gilab (one line in the top-level CMakeLists.txt) or on its own against an installed gilab
// (CMakeLists.txt here, docs/tutorial.md "Your technique in your own repository").
#include <glm/glm.hpp>

#include "core/passes/gbuffer.h"
#include "core/passes/shared_passes.h"
#include "core/technique/registry.h"
#include "core/technique/technique.h"
#include "core/vk/barrier.h"
#include "core/vk/descriptors.h"
#include "core/vk/image.h"
#include "core/vk/pipeline.h"

namespace gilab {

/** A uniform, unoccluded ambient radiance reflected by a Lambertian surface: indirect = rho L_a. */
class AmbientTechnique final : public Technique {
public:
    static TechniqueInfo describe() {
        TechniqueInfo info;
        info.id = "ambient";
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

        PassScope pass(ctx, cmd, "ambient");  // timed as "ambient/ambient"
        m_pipeline.bind(cmd);
        const VkDescriptorSet set = m_set.handle();
        vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, m_layout.handle(), 0, 1, &set,
                                0, nullptr);
        m_layout.push(cmd, push);
        vk::dispatch2D(cmd, ctx.width, ctx.height);  // 8 x 8 groups, as in the shader
        vk::memoryBarrier(cmd);
    }

    /** The run-time name of shaders/ambient.comp: "<id>/<file in shaders/>". */
    static constexpr const char* kShader = "ambient/ambient.comp";

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
GILAB_REGISTER_TECHNIQUE(AmbientTechnique)

}  // namespace gilab
