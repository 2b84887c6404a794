#pragma once
/**
 * DVS per-pixel pass P1 "trace" (notes 003 §2.8): one compute dispatch over the G-buffer that
 * traces the diffuse cones (+ specular cone, AO, optional cone shadows for the direct layer)
 * through the filtered radiance pyramid. Shader: techniques/dvs/shaders/trace.comp.
 * Targets (indirect, direct) are bound on first use and re-bound if their views change.
 */
#include <vulkan/vulkan.h>

#include "core/vk/buffer.h"
#include "core/vk/descriptors.h"
#include "core/vk/image.h"
#include "core/vk/pipeline.h"
#include "dvs_settings.h"

namespace gilab {

namespace vk {
class Context;
}
class SharedPasses;
class VoxelRadiance;
struct Camera;

class DvsPixelTrace {
public:
    DvsPixelTrace(vk::Context& ctx, SharedPasses& shared, VoxelRadiance& radiance,
                  const std::string& memoryTag);
    DvsPixelTrace(const DvsPixelTrace&) = delete;
    DvsPixelTrace& operator=(const DvsPixelTrace&) = delete;

    /** Updates the uniforms (host-visible; the previous frame has finished) and records. */
    void record(VkCommandBuffer cmd, const DvsSettings& settings, const Camera& camera,
                vk::Image& indirect, vk::Image& direct);
    /** AO visibility in [0, 1] (rgb), RGBA32F, GENERAL after the first record(). */
    vk::Image& aoImage() { return m_ao; }

private:
    vk::Context& m_ctx;
    SharedPasses& m_shared;
    VoxelRadiance& m_radiance;
    vk::Image m_ao;
    vk::Buffer m_uniforms;
    vk::DescriptorSetLayout m_setLayout;
    vk::DescriptorSet m_set;
    vk::PipelineLayout m_layout;
    vk::ComputePipeline m_pipeline;
    VkImageView m_boundIndirect = VK_NULL_HANDLE;
    VkImageView m_boundDirect = VK_NULL_HANDLE;
};

}  // namespace gilab
