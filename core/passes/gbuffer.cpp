#include "core/passes/gbuffer.h"

#include <glm/glm.hpp>

#include "core/gpu/gpu_scene.h"
#include "core/util/error.h"
#include "core/vk/context.h"
#include "core/vk/rendering.h"

namespace gilab {
namespace {

/** Mirrors shaders/common/gbuffer_pc.glsl. */
struct GBufferPush {
    glm::mat4 viewProj;
    glm::vec4 cameraPosition;
};
static_assert(sizeof(GBufferPush) == 80);

vk::Image makeLayer(vk::Context& ctx, uint32_t width, uint32_t height, const char* name) {
    vk::ImageDesc desc;
    desc.kind = vk::ImageKind::Image2D;
    desc.format = GBufferPass::kColorFormat;
    desc.width = width;
    desc.height = height;
    desc.usage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_STORAGE_BIT |
                 VK_IMAGE_USAGE_SAMPLED_BIT;
    desc.name = std::string("shared/gbuffer.") + name;
    return vk::Image(ctx, desc);
}

}  // namespace

GBufferPass::GBufferPass(vk::Context& ctx, const vk::GpuScene& scene, uint32_t width,
                         uint32_t height)
    : m_ctx(ctx), m_scene(scene) {
    if (width == 0 || height == 0) throw Error("GBufferPass: resolution must be non-zero");
    m_gbuffer.width = width;
    m_gbuffer.height = height;
    m_gbuffer.position = makeLayer(ctx, width, height, "position");
    m_gbuffer.normal = makeLayer(ctx, width, height, "normal");
    m_gbuffer.albedo = makeLayer(ctx, width, height, "albedo");
    m_gbuffer.material = makeLayer(ctx, width, height, "material");
    m_gbuffer.emission = makeLayer(ctx, width, height, "emission");

    vk::ImageDesc depth;
    depth.format = kDepthFormat;
    depth.width = width;
    depth.height = height;
    depth.usage = VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT;
    depth.name = "shared/gbuffer.depth";
    m_gbuffer.depth = vk::Image(ctx, depth);

    m_layout = vk::PipelineLayout(ctx, {scene.layout().handle()}, sizeof(GBufferPush));
    vk::GraphicsPipelineDesc desc;
    desc.vertexShader = "common/gbuffer.vert";
    desc.fragmentShader = "common/gbuffer.frag";
    desc.sceneVertexInput = false;  // vertices are pulled from the scene set
    desc.colorFormats.assign(5, kColorFormat);
    desc.depthFormat = kDepthFormat;
    desc.depthTest = true;
    desc.depthWrite = true;
    desc.depthCompare = VK_COMPARE_OP_LESS;
    desc.cull = VK_CULL_MODE_NONE;
    desc.name = "shared/gbuffer";
    m_pipeline = vk::GraphicsPipeline(ctx, desc, m_layout);
}

void GBufferPass::record(VkCommandBuffer cmd, const Camera& camera) {
    vk::Image* layers[] = {&m_gbuffer.position, &m_gbuffer.normal, &m_gbuffer.albedo,
                           &m_gbuffer.material, &m_gbuffer.emission};
    std::vector<vk::ColorTarget> targets;
    for (vk::Image* layer : layers) {
        layer->transition(cmd, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL);
        targets.push_back({layer->view(), VkClearColorValue{{0.0f, 0.0f, 0.0f, 0.0f}},
                           VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL});
    }
    m_gbuffer.depth.transition(cmd, VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL);

    const float aspect = float(m_gbuffer.width) / float(m_gbuffer.height);
    GBufferPush push{camera.projection(aspect) * camera.view(), glm::vec4(camera.position, 1.0f)};
    {
        vk::DepthTarget depthTarget;
        depthTarget.view = m_gbuffer.depth.view();
        depthTarget.clear = 1.0f;
        vk::RenderingScope scope(cmd, {m_gbuffer.width, m_gbuffer.height}, targets, depthTarget);
        if (m_scene.triangleCount() > 0) {
            m_pipeline.bind(cmd);
            VkDescriptorSet set = m_scene.set().handle();
            vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, m_layout.handle(), 0, 1,
                                    &set, 0, nullptr);
            vkCmdPushConstants(cmd, m_layout.handle(), m_layout.pushStages(), 0, sizeof(push),
                               &push);
            vkCmdDraw(cmd, 3 * m_scene.triangleCount(), 1, 0, 0);
        }
    }
    for (vk::Image* layer : layers)
        layer->transition(cmd, VK_IMAGE_LAYOUT_GENERAL);
    m_gbuffer.depth.transition(cmd, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
}

Image computeLinearDepth(const std::vector<float>& positionRgba, uint32_t width, uint32_t height,
                         const Camera& camera) {
    if (positionRgba.size() < size_t(width) * height * 4) {
        throw Error("computeLinearDepth: position layer has fewer than width*height*4 values");
    }
    Image depth(int(width), int(height), 1, 0.0f);
    const glm::vec3 forward = camera.forward();
    for (uint32_t y = 0; y < height; ++y) {
        for (uint32_t x = 0; x < width; ++x) {
            const float* p = &positionRgba[(size_t(y) * width + x) * 4];
            if (p[3] <= 0.0f) continue;
            depth.at(int(x), int(y), 0) =
                glm::dot(glm::vec3(p[0], p[1], p[2]) - camera.position, forward);
        }
    }
    return depth;
}

}  // namespace gilab
