#include "core/passes/distance_map.h"

#include <cmath>

#include "core/gpu/gpu_scene.h"
#include "core/passes/light_view.h"
#include "core/passes/pass_light.h"
#include "core/scene/camera.h"
#include "core/util/error.h"
#include "core/vk/context.h"
#include "core/vk/rendering.h"

namespace gilab {

DistanceView DistanceView::fromPassLight(const PassLight& light) {
    if (uint32_t(light.shadow.x) != kShadowMap2D) {
        throw Error(
            "DistanceView: the light has no 2D shadow view (a point light or a spot "
            "wider than the 2D maps take)");
    }
    DistanceView v;
    v.viewProj = light.viewProj;
    const bool ortho = light.shadow.w > 0.5f;
    v.origin = glm::vec4(ortho ? glm::vec3(light.origin) : glm::vec3(light.positionType),
                         ortho ? 1.0f : 0.0f);
    v.direction = glm::vec4(glm::vec3(light.direction), 0.0f);
    return v;
}

DistanceView DistanceView::fromCamera(const Camera& camera, float aspect) {
    DistanceView v;
    const float tanHalf = std::tan(0.5f * camera.vfovRad);
    // Image y points down (light_view.h): the y axis is -up; x is scaled by the aspect.
    v.viewProj = pinholeViewProj(camera.position, camera.forward(), camera.right() / aspect,
                                 -camera.trueUp(), tanHalf, camera.nearZ);
    v.origin = glm::vec4(camera.position, 0.0f);
    v.direction = glm::vec4(camera.forward(), 0.0f);
    return v;
}

vk::GraphicsPipelineDesc distancePipelineDesc(const std::string& name) {
    vk::GraphicsPipelineDesc p;
    p.vertexShader = "common/shadow.vert";
    p.fragmentShader = "common/shadow.frag";
    p.sceneVertexInput = false;
    p.colorFormats = {VK_FORMAT_R32_SFLOAT};
    p.depthFormat = VK_FORMAT_D32_SFLOAT;
    p.depthCompare = VK_COMPARE_OP_GREATER;  // reversed-Z
    p.cull = VK_CULL_MODE_NONE;
    p.name = name;
    return p;
}

DistanceMap::DistanceMap(vk::Context& ctx, const vk::GpuScene& scene, uint32_t width,
                         uint32_t height, const std::string& name)
    : m_scene(scene) {
    if (width == 0 || height == 0) throw Error("DistanceMap " + name + ": empty size");
    vk::ImageDesc desc;
    desc.format = VK_FORMAT_R32_SFLOAT;
    desc.width = width;
    desc.height = height;
    desc.usage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT |
                 VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
    desc.name = name;
    m_distance = vk::Image(ctx, desc);
    vk::ImageDesc depth;
    depth.format = VK_FORMAT_D32_SFLOAT;
    depth.width = width;
    depth.height = height;
    depth.usage = VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT;
    depth.name = name + ".depth";
    m_depth = vk::Image(ctx, depth);

    m_layout = vk::PipelineLayout(ctx, {scene.layout().handle()}, sizeof(DistanceView));
    m_pipeline = vk::GraphicsPipeline(ctx, distancePipelineDesc(name), m_layout);
}

void DistanceMap::record(VkCommandBuffer cmd, const DistanceView& view) {
    m_distance.transition(cmd, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL);
    m_depth.transition(cmd, VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL);
    {
        vk::ColorTarget color{m_distance.view(), VkClearColorValue{{kFar, 0.0f, 0.0f, 0.0f}},
                              VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL};
        vk::DepthTarget depth;
        depth.view = m_depth.view();
        depth.clear = 0.0f;  // reversed-Z
        depth.store = false;
        vk::RenderingScope scope(cmd, {m_distance.width(), m_distance.height()}, {color}, depth);
        if (m_scene.triangleCount() > 0) {
            m_pipeline.bind(cmd);
            VkDescriptorSet set = m_scene.set().handle();
            vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, m_layout.handle(), 0, 1,
                                    &set, 0, nullptr);
            m_layout.push(cmd, view);
            vkCmdDraw(cmd, 3 * m_scene.triangleCount(), 1, 0, 0);
        }
    }
    m_distance.transition(cmd, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
}

}  // namespace gilab
