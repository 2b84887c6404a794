#pragma once
/**
 * Reflective shadow map (Dachsbacher & Stamminger 2005) of one light and the first-bounce VPLs
 * drawn from it, for the VPL techniques (docs/vpl.md).
 *
 * The RSM is rendered with the light's 2D view from the pass light table (spot: perspective over
 * the outer cone; directional: orthographic over the scene's bounding sphere; the same views as
 * the shadow maps), at its own resolution, apart from the direct-light shadow maps (Aranha et al.
 * §III-A: "shadow map and RSM generation are decoupled"). Layers (RGBA32F, GENERAL after record):
 * position, normal (on the light's side), albedo; background texels are 0.
 *
 * recordVpls() draws n VPLs at the fixed Hammersley points (Eq. 1; a technique's `seed` shifts
 * them toroidally, a Cranley-Patterson rotation) with flux in watts from the
 * texel's area (directional) or solid angle (spot): see shaders/common/rsm_vpls.comp.
 */
#include <cstdint>
#include <string>

#include <vulkan/vulkan.h>
#include <glm/glm.hpp>

#include "core/vk/descriptors.h"
#include "core/vk/image.h"
#include "core/vk/pipeline.h"

namespace gilab {
namespace vk {
class Buffer;
class Context;
class GpuScene;
}  // namespace vk
struct PassLight;
struct Scene;

/**
 * The scene light a VPL technique renders its RSM from: `requested` (a scene light index) when
 * it is >= 0, else the first spot (outer cone <= 85 deg) or directional light. Returns -1 with
 * the reason in `*why` when there is none or `requested` cannot have an RSM.
 */
int rsmMainLight(const Scene& scene, int requested, std::string* why);

class ReflectiveShadowMap {
public:
    /** passLights: the pass light table buffer (ShadowMaps::lightBuffer()). */
    ReflectiveShadowMap(vk::Context& ctx, const vk::GpuScene& scene, const vk::Buffer& passLights,
                        uint32_t size, const std::string& tag);
    ReflectiveShadowMap(const ReflectiveShadowMap&) = delete;
    ReflectiveShadowMap& operator=(const ReflectiveShadowMap&) = delete;

    /** True when the pass light has a 2D view an RSM can use (spot <= 85 deg, directional). */
    static bool supports(const PassLight& light);
    /** Renders the RSM of pass light `light` (whose table entry is `entry`). */
    void record(VkCommandBuffer cmd, const PassLight& entry, uint32_t light);
    /** Writes `count` VPLs from the last record() to vpls[first ...] (bounce 1, unshadowed), at
     *  the Hammersley points toroidally shifted by `shift` (vpl::cranleyPattersonShift of the
     *  technique's seed; (0, 0), the default, is the unshifted set). */
    void recordVpls(VkCommandBuffer cmd, const vk::Buffer& vpls, uint32_t first, uint32_t count,
                    glm::vec2 shift = glm::vec2(0.0f));

    vk::Image& position() { return m_position; }
    vk::Image& normal() { return m_normal; }
    vk::Image& albedo() { return m_albedo; }
    uint32_t size() const { return m_position.width(); }

private:
    const vk::GpuScene& m_scene;
    vk::Image m_position, m_normal, m_albedo, m_depth;
    vk::PipelineLayout m_rasterLayout;
    vk::GraphicsPipeline m_raster;
    vk::DescriptorSetLayout m_setLayout;
    vk::DescriptorSet m_set;
    vk::PipelineLayout m_vplLayout;
    vk::ComputePipeline m_vpls;
    VkBuffer m_boundVpls = VK_NULL_HANDLE;
    // From the last record(): the sampling push constants.
    glm::vec4 m_axis{0.0f};
    uint32_t m_light = 0;
    bool m_perspective = false;
};

}  // namespace gilab
