#include "core/passes/direct_light.h"

#include <glm/glm.hpp>

#include "core/gpu/gpu_scene.h"
#include "core/passes/gbuffer.h"
#include "core/passes/shadow_maps.h"
#include "core/vk/barrier.h"
#include "core/vk/context.h"

namespace gilab {
namespace {

/** Mirrors DirectPush in shaders/common/direct_light.comp. */
struct DirectPush {
    glm::vec4 cameraPosition;
    glm::uvec4 sizeLights;  // width, height, light count, shadows on
    glm::uvec4 areaLights;  // first emitter-sample entry, emissive triangles (0 = no analytic)
};

/** Bindings of direct_light.comp (set 1; set 0 is the scene): 0-3 G-buffer, 4 output,
 *  5 emissive triangles, 6-9 shadow.glsl. */
constexpr uint32_t kOutputBinding = 4;
constexpr uint32_t kPolygonBinding = 5;
constexpr uint32_t kShadowBinding = 6;

}  // namespace

DirectLightPass::DirectLightPass(vk::Context& ctx, const vk::GpuScene& scene, GBuffer& gbuffer,
                                 ShadowMaps& shadows, bool analyticAreaLights)
    : m_gbuffer(gbuffer), m_shadows(shadows), m_analyticAreaLights(analyticAreaLights) {
    // The lights come from the pass light table (ShadowMaps); the scene set gives each pixel's
    // triangle plane to the shadow lookups.
    m_sceneSet = scene.set().handle();
    vk::ImageDesc desc;
    desc.format = VK_FORMAT_R32G32B32A32_SFLOAT;
    desc.width = gbuffer.width;
    desc.height = gbuffer.height;
    desc.usage = VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT;
    desc.name = "shared/direct";
    m_output = vk::Image(ctx, desc);

    const VkShaderStageFlags stage = VK_SHADER_STAGE_COMPUTE_BIT;
    std::vector<vk::DescriptorBinding> bindings;
    for (uint32_t b = 0; b <= kOutputBinding; ++b) {
        bindings.push_back({b, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1, stage});
    }
    bindings.push_back({kPolygonBinding, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, stage});
    for (const vk::DescriptorBinding& b : ShadowMaps::descriptorBindings(kShadowBinding, stage)) {
        bindings.push_back(b);
    }
    m_setLayout = vk::DescriptorSetLayout(ctx, bindings, "shared/direct_light");
    m_set = vk::DescriptorSet(ctx, m_setLayout, 0, "shared/direct_light");
    m_set.writeStorageImage(0, gbuffer.position.view());
    m_set.writeStorageImage(1, gbuffer.normal.view());
    m_set.writeStorageImage(2, gbuffer.albedo.view());
    m_set.writeStorageImage(3, gbuffer.material.view());
    m_set.writeStorageImage(kOutputBinding, m_output.view());
    m_set.writeBuffer(kPolygonBinding, shadows.emitterPolygonBuffer());
    shadows.writeDescriptors(m_set, kShadowBinding);

    m_layout = vk::PipelineLayout(ctx, {scene.layout().handle(), m_setLayout.handle()},
                                  sizeof(DirectPush));
    m_pipeline = vk::ComputePipeline(ctx, "common/direct_light.comp", m_layout);
}

void DirectLightPass::record(VkCommandBuffer cmd, const Camera& camera) {
    m_output.transition(cmd, VK_IMAGE_LAYOUT_GENERAL);
    m_pipeline.bind(cmd);
    const VkDescriptorSet sets[2] = {m_sceneSet, m_set.handle()};
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, m_layout.handle(), 0, 2, sets, 0,
                            nullptr);
    DirectPush push{
        glm::vec4(camera.position, 1.0f),
        glm::uvec4(m_gbuffer.width, m_gbuffer.height, m_shadows.lightCount(),
                   m_shadows.settings().enabled ? 1u : 0u),
        glm::uvec4(m_shadows.sceneLightCount(),
                   m_analyticAreaLights ? m_shadows.emitterPolygonCount() : 0u, 0u, 0u)};
    vkCmdPushConstants(cmd, m_layout.handle(), m_layout.pushStages(), 0, sizeof(push), &push);
    vk::dispatch2D(cmd, m_gbuffer.width, m_gbuffer.height);
    vk::memoryBarrier(cmd);
}

}  // namespace gilab
