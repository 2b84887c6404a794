#pragma once
/**
 * Direct light pass (compute, one thread per pixel): reads the G-buffer and the shadow maps and
 * writes `direct` (RGBA32F): rgb = sum over the pass lights (scene lights and emitter samples)
 * of f(wi, wo) * E * V, a = 1 on covered pixels, 0 on the background. wo points to the camera.
 * Area lights: the emitter samples' shadowed sum is rescaled to the exact unoccluded irradiance
 * of the emissive triangles (ratio estimator), unless analyticAreaLights is off.
 * Exact by construction: no ambient term, no clamping (shaders/common/direct_light.comp).
 * Inputs: G-buffer colour layers in GENERAL, shadow maps in SHADER_READ_ONLY_OPTIMAL, as left
 * by GBufferPass::record and ShadowMaps. The output is left in GENERAL after a full barrier.
 */
#include <cstdint>

#include <vulkan/vulkan.h>

#include "core/scene/camera.h"
#include "core/vk/descriptors.h"
#include "core/vk/image.h"
#include "core/vk/pipeline.h"

namespace gilab {

namespace vk {
class Context;
class GpuScene;
}  // namespace vk

struct GBuffer;
class ShadowMaps;

class DirectLightPass {
public:
    /** analyticAreaLights: emitter samples give only visibility; the unoccluded irradiance of
     *  the emissive triangles is exact (direct_light.comp). */
    DirectLightPass(vk::Context& ctx, const vk::GpuScene& scene, GBuffer& gbuffer,
                    ShadowMaps& shadows, bool analyticAreaLights = true);
    DirectLightPass(const DirectLightPass&) = delete;
    DirectLightPass& operator=(const DirectLightPass&) = delete;

    void record(VkCommandBuffer cmd, const Camera& camera);
    vk::Image& output() { return m_output; }

private:
    GBuffer& m_gbuffer;
    ShadowMaps& m_shadows;
    bool m_analyticAreaLights = true;
    vk::Image m_output;
    vk::DescriptorSetLayout m_setLayout;
    vk::DescriptorSet m_set;
    VkDescriptorSet m_sceneSet = VK_NULL_HANDLE;  // the GpuScene's set (set 0)
    vk::PipelineLayout m_layout;
    vk::ComputePipeline m_pipeline;
};

}  // namespace gilab
