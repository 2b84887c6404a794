#include "core/vpl/rsm.h"

#include <cmath>
#include <string>

#include "core/gpu/gpu_scene.h"
#include "core/passes/pass_light.h"
#include "core/scene/scene.h"
#include "core/util/error.h"
#include "core/vk/barrier.h"
#include "core/vk/buffer.h"
#include "core/vk/context.h"
#include "core/vk/rendering.h"

namespace gilab {
namespace {

struct RsmPush {  // mirrors shaders/common/rsm_pc.glsl
    glm::mat4 viewProj;
    glm::vec4 toLight;
};
struct VplPush {  // mirrors rsm_vpls.comp
    glm::vec4 axis;
    uint32_t light, count, first, perspective;
    glm::vec2 shift;
};

glm::vec3 row(const glm::mat4& m, int r) {
    return {m[0][r], m[1][r], m[2][r]};
}

/**
 * A directional light's shadow view covers the scene's bounding sphere; its RSM is fitted to the
 * rectangle the scene's bounding box projects to instead (x and y of the same view), so fewer
 * texels, and fewer VPLs, fall on nothing. Depth and orientation stay the view's.
 */
glm::mat4 fitOrthoToBounds(const glm::mat4& viewProj, const Bounds& b) {
    if (!b.valid()) return viewProj;
    glm::vec2 lo(1e30f), hi(-1e30f);
    for (int i = 0; i < 8; ++i) {
        const glm::vec3 corner((i & 1) ? b.hi.x : b.lo.x, (i & 2) ? b.hi.y : b.lo.y,
                               (i & 4) ? b.hi.z : b.lo.z);
        const glm::vec4 c = viewProj * glm::vec4(corner, 1.0f);
        lo = glm::min(lo, glm::vec2(c) / c.w);
        hi = glm::max(hi, glm::vec2(c) / c.w);
    }
    lo = glm::max(lo, glm::vec2(-1.0f));
    hi = glm::min(hi, glm::vec2(1.0f));
    // Half a percent of margin so no surface sits on the border texels.
    const glm::vec2 half = 0.505f * glm::max(hi - lo, glm::vec2(1e-6f));
    const glm::vec2 centre = 0.5f * (lo + hi);
    glm::mat4 remap(1.0f);
    remap[0][0] = 1.0f / half.x;
    remap[1][1] = 1.0f / half.y;
    remap[3][0] = -centre.x / half.x;
    remap[3][1] = -centre.y / half.y;
    return remap * viewProj;
}

}  // namespace

int rsmMainLight(const Scene& scene, int requested, std::string* why) {
    constexpr float kMaxSpotOuterRad = 1.4835299f;  // 85 deg: wider spots have no 2D view
    auto candidate = [&](const Light& l) {
        return l.type == LightType::Directional ||
               (l.type == LightType::Spot && l.outerConeRad <= kMaxSpotOuterRad);
    };
    if (requested >= 0) {
        if (requested >= int(scene.lights.size())) {
            if (why)
                *why = "light = " + std::to_string(requested) + " but the scene has " +
                       std::to_string(scene.lights.size()) + " light(s)";
            return -1;
        }
        if (!candidate(scene.lights[size_t(requested)])) {
            if (why)
                *why = "light " + std::to_string(requested) + " ('" +
                       scene.lights[size_t(requested)].name +
                       "') is not a spot (<= 85 deg) or directional light: it has no RSM view";
            return -1;
        }
        return requested;
    }
    for (size_t i = 0; i < scene.lights.size(); ++i)
        if (candidate(scene.lights[i])) return int(i);
    if (why)
        *why =
            "needs a spot (<= 85 deg) or directional light for its reflective shadow map (the "
            "VPLs' main light)";
    return -1;
}

ReflectiveShadowMap::ReflectiveShadowMap(vk::Context& ctx, const vk::GpuScene& scene,
                                         const vk::Buffer& passLights, uint32_t size,
                                         const std::string& tag)
    : m_scene(scene) {
    if (size == 0) throw Error(tag + ": empty reflective shadow map");
    const VkImageUsageFlags color =
        VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_STORAGE_BIT;
    auto layer = [&](VkFormat format, VkImageUsageFlags usage, const std::string& name) {
        return vk::Image(ctx, vk::imageDesc2D(size, size, format, usage, tag + name));
    };
    m_position = layer(VK_FORMAT_R32G32B32A32_SFLOAT, color, "/rsm.position");
    m_normal = layer(VK_FORMAT_R32G32B32A32_SFLOAT, color, "/rsm.normal");
    m_albedo = layer(VK_FORMAT_R32G32B32A32_SFLOAT, color, "/rsm.albedo");
    m_depth =
        layer(VK_FORMAT_D32_SFLOAT, VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT, "/rsm.depth");

    m_rasterLayout = vk::PipelineLayout(ctx, {scene.layout().handle()}, sizeof(RsmPush));
    vk::GraphicsPipelineDesc p;
    p.vertexShader = "common/rsm.vert";
    p.fragmentShader = "common/rsm.frag";
    p.sceneVertexInput = false;
    p.colorFormats.assign(3, VK_FORMAT_R32G32B32A32_SFLOAT);
    p.depthFormat = VK_FORMAT_D32_SFLOAT;
    p.depthCompare = VK_COMPARE_OP_GREATER;  // reversed-Z light views (light_view.h)
    p.cull = VK_CULL_MODE_NONE;
    p.name = tag + "/rsm";
    m_raster = vk::GraphicsPipeline(ctx, p, m_rasterLayout);

    const VkShaderStageFlags cs = VK_SHADER_STAGE_COMPUTE_BIT;
    m_setLayout = vk::DescriptorSetLayout(ctx,
                                          {{0, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1, cs},
                                           {1, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1, cs},
                                           {2, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1, cs},
                                           {3, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, cs},
                                           {4, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, cs}},
                                          tag + "/rsm_vpls");
    m_set = vk::DescriptorSet(ctx, m_setLayout, 0, tag + "/rsm_vpls");
    m_set.writeStorageImage(0, m_position.view());
    m_set.writeStorageImage(1, m_normal.view());
    m_set.writeStorageImage(2, m_albedo.view());
    m_set.writeBuffer(3, passLights);
    m_vplLayout = vk::PipelineLayout(ctx, {m_setLayout.handle()}, sizeof(VplPush));
    m_vpls = vk::ComputePipeline(ctx, "common/rsm_vpls.comp", m_vplLayout);
}

bool ReflectiveShadowMap::supports(const PassLight& light) {
    return uint32_t(light.shadow.x) == kShadowMap2D &&
           (uint32_t(light.positionType.w) == kPassLightSpot ||
            uint32_t(light.positionType.w) == kPassLightDirectional);
}

void ReflectiveShadowMap::record(VkCommandBuffer cmd, const PassLight& entry, uint32_t light) {
    if (!supports(entry))
        throw Error("reflective shadow map: pass light " + std::to_string(light) +
                    " is not a spot or directional light with a 2D view");
    const bool directional = uint32_t(entry.positionType.w) == kPassLightDirectional;
    const glm::mat4 vp = directional ? fitOrthoToBounds(entry.viewProj, m_scene.scene().caps.bounds)
                                     : entry.viewProj;
    RsmPush push{vp, directional ? glm::vec4(-glm::vec3(entry.direction), 1.0f)
                                 : glm::vec4(glm::vec3(entry.positionType), 0.0f)};
    // Texel footprint (docs/vpl.md): the view maps a texel to 2 / (W |r0|) x 2 / (H |r1|) on the
    // plane at unit distance (perspective, scaled by |r3|^2) or in the world (orthographic).
    const float n = float(size());
    const float s = directional ? 1.0f : glm::length(row(vp, 3));
    const float area = 4.0f * s * s / (n * n * glm::length(row(vp, 0)) * glm::length(row(vp, 1)));
    m_axis = glm::vec4(directional ? glm::vec3(entry.direction) : row(vp, 3) / s, area);
    m_light = light;
    m_perspective = !directional;

    for (vk::Image* img : {&m_position, &m_normal, &m_albedo})
        img->transition(cmd, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL);
    m_depth.transition(cmd, VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL);
    {
        const VkClearColorValue zero{{0.0f, 0.0f, 0.0f, 0.0f}};
        vk::DepthTarget depth;
        depth.view = m_depth.view();
        depth.clear = 0.0f;  // reversed-Z
        depth.store = false;
        vk::RenderingScope scope(
            cmd, m_position.extent2D(),
            {{m_position.view(), zero}, {m_normal.view(), zero}, {m_albedo.view(), zero}}, depth);
        if (m_scene.triangleCount() > 0) {
            m_raster.bind(cmd);
            VkDescriptorSet set = m_scene.set().handle();
            vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, m_rasterLayout.handle(),
                                    0, 1, &set, 0, nullptr);
            m_rasterLayout.push(cmd, push);
            vkCmdDraw(cmd, 3 * m_scene.triangleCount(), 1, 0, 0);
        }
    }
    for (vk::Image* img : {&m_position, &m_normal, &m_albedo})
        img->transition(cmd, VK_IMAGE_LAYOUT_GENERAL);
}

void ReflectiveShadowMap::recordVpls(VkCommandBuffer cmd, const vk::Buffer& vpls, uint32_t first,
                                     uint32_t count, glm::vec2 shift) {
    if (count == 0) return;
    if (vpls.handle() != m_boundVpls) {  // synchronous submissions: safe to rewrite
        m_set.writeBuffer(4, vpls);
        m_boundVpls = vpls.handle();
    }
    m_vpls.bind(cmd);
    VkDescriptorSet set = m_set.handle();
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, m_vplLayout.handle(), 0, 1, &set,
                            0, nullptr);
    const VplPush push{m_axis, m_light, count, first, m_perspective ? 1u : 0u, shift};
    m_vplLayout.push(cmd, push);
    vk::dispatch1D(cmd, count, 64);
    vk::memoryBarrier(cmd);
}

}  // namespace gilab
