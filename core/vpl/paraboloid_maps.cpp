#include "core/vpl/paraboloid_maps.h"

#include <algorithm>
#include <optional>

#include "core/gpu/gpu_scene.h"
#include "core/util/error.h"
#include "core/vk/buffer.h"
#include "core/vk/context.h"
#include "core/vk/rendering.h"

namespace gilab {
namespace {

struct ParaboloidPush {  // mirrors shaders/common/paraboloid_pc.glsl
    float far, maxEdgeAngle;
    uint32_t maxSubdivision, resolution;
};

constexpr VkFormat kPositionFormat = VK_FORMAT_R32G32B32A32_SFLOAT;
constexpr VkFormat kAttributeFormat = VK_FORMAT_R16G16B16A16_SFLOAT;

vk::Image layers(vk::Context& ctx, const ParaboloidSettings& s, VkFormat format,
                 VkImageUsageFlags usage, const std::string& name) {
    vk::ImageDesc d;
    d.kind = vk::ImageKind::Image2DArray;
    d.format = format;
    d.width = s.resolution;
    d.height = s.resolution;
    d.layers = s.layers;
    d.usage = usage;
    d.name = name;
    return vk::Image(ctx, d);
}

}  // namespace

ParaboloidMaps::ParaboloidMaps(vk::Context& ctx, const vk::GpuScene& scene,
                               const vk::Buffer& clusters, const ParaboloidSettings& settings,
                               const std::string& tag)
    : m_scene(scene), m_settings(settings) {
    if (settings.resolution == 0 || settings.layers == 0)
        throw Error(tag + ": empty paraboloid maps");
    const uint32_t maxLayers = ctx.properties().limits.maxFramebufferLayers;
    if (settings.layers > maxLayers)
        throw Error(tag + ": " + std::to_string(settings.layers) +
                    " paraboloid layers, above the device's maxFramebufferLayers (" +
                    std::to_string(maxLayers) + ")");
    m_settings.maxSubdivision = std::clamp(settings.maxSubdivision, 1u, 4u);
    const VkImageUsageFlags color =
        VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_STORAGE_BIT;
    m_position = layers(ctx, m_settings, kPositionFormat, color, tag + "/paraboloid.position");
    m_normal = layers(ctx, m_settings, kAttributeFormat, color, tag + "/paraboloid.normal");
    m_albedo = layers(ctx, m_settings, kAttributeFormat, color, tag + "/paraboloid.albedo");
    m_depth = layers(ctx, m_settings, VK_FORMAT_D32_SFLOAT,
                     VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT, tag + "/paraboloid.depth");

    const VkShaderStageFlags stages = VK_SHADER_STAGE_GEOMETRY_BIT | VK_SHADER_STAGE_FRAGMENT_BIT;
    m_setLayout = vk::DescriptorSetLayout(ctx, {{0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, stages}},
                                          tag + "/paraboloid");
    m_set = vk::DescriptorSet(ctx, m_setLayout, 0, tag + "/paraboloid");
    m_set.writeBuffer(0, clusters);
    m_layout = vk::PipelineLayout(ctx, {scene.layout().handle(), m_setLayout.handle()},
                                  sizeof(ParaboloidPush));
    vk::GraphicsPipelineDesc p;
    p.vertexShader = "common/paraboloid.vert";
    p.geometryShader = "common/paraboloid.geom";
    p.fragmentShader = "common/paraboloid.frag";
    p.sceneVertexInput = false;
    p.colorFormats = {kPositionFormat, kAttributeFormat, kAttributeFormat};
    p.depthFormat = VK_FORMAT_D32_SFLOAT;
    p.depthCompare = VK_COMPARE_OP_LESS;  // radial distance / far
    p.cull = VK_CULL_MODE_NONE;
    p.name = tag + "/paraboloid";
    m_pipeline = vk::GraphicsPipeline(ctx, p, m_layout);
}

void ParaboloidMaps::setSubdivision(uint32_t maxSubdivision, float maxEdgeAngleRad) {
    m_settings.maxSubdivision = std::clamp(maxSubdivision, 1u, 4u);
    m_settings.maxEdgeAngleRad = maxEdgeAngleRad;
}

void ParaboloidMaps::record(VkCommandBuffer cmd, uint32_t first, uint32_t count) {
    first = std::min(first, m_settings.layers);
    count = std::min(count, m_settings.layers - first);
    for (vk::Image* img : {&m_position, &m_normal, &m_albedo})
        img->transition(cmd, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL);
    m_depth.transition(cmd, VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL);
    {
        // Layers below `first` are loaded unchanged (nothing is drawn into them); the depth is
        // cleared every time, as only the drawn layers use it.
        std::optional<VkClearColorValue> clear;
        if (first == 0) clear = VkClearColorValue{{0.0f, 0.0f, 0.0f, 0.0f}};
        vk::DepthTarget depth;
        depth.view = m_depth.view();
        depth.clear = 1.0f;
        depth.store = false;
        vk::RenderingScope scope(
            cmd, m_position.extent2D(),
            {{m_position.view(), clear}, {m_normal.view(), clear}, {m_albedo.view(), clear}}, depth,
            m_settings.layers);
        if (m_scene.triangleCount() > 0 && count > 0) {
            m_pipeline.bind(cmd);
            VkDescriptorSet sets[2] = {m_scene.set().handle(), m_set.handle()};
            vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, m_layout.handle(), 0, 2,
                                    sets, 0, nullptr);
            const ParaboloidPush push{m_settings.far, m_settings.maxEdgeAngleRad,
                                      m_settings.maxSubdivision, m_settings.resolution};
            m_layout.push(cmd, push);
            // Instance i draws layer i (paraboloid.vert): firstInstance picks the range.
            vkCmdDraw(cmd, 3 * m_scene.triangleCount(), count, 0, first);
        }
    }
    for (vk::Image* img : {&m_position, &m_normal, &m_albedo})
        img->transition(cmd, VK_IMAGE_LAYOUT_GENERAL);
}

uint64_t ParaboloidMaps::bytes() const {
    const uint64_t texels =
        uint64_t(m_settings.resolution) * m_settings.resolution * m_settings.layers;
    return texels * (16 + 8 + 8 + 4);
}

}  // namespace gilab
