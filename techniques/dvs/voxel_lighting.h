#pragma once
/**
 * The per-voxel lighting passes of deferred voxel shading (notes 003 §2.4-2.6):
 *   L1 recordDirect()  every occupied voxel lit by every pass light (scene punctual lights and
 *                      the emitter samples standing in for emissive triangles), occlusion from
 *                      the shared shadow maps or by marching the voxel grid; writes base()
 *   G1 recordBounce()  per-voxel diffuse cones through the filtered direct radiance; writes
 *                      base = direct + first bounce (via a scratch volume, so the cones may read
 *                      every level while the result is written)
 * The caller runs VoxelRadiance::filter() after each (F). Inputs: the Voxelizer's volumes (in
 * SHADER_READ_ONLY_OPTIMAL) and the ShadowMaps (rendered). Shaders:
 * techniques/dvs/shaders/voxel_*.comp.
 */
#include <memory>

#include <vulkan/vulkan.h>

#include "core/vk/buffer.h"
#include "core/vk/descriptors.h"
#include "core/vk/image.h"
#include "core/vk/pipeline.h"
#include "core/vk/sampler.h"
#include "dvs_settings.h"

namespace gilab {

namespace vk {
class Context;
}
class Voxelizer;
class VoxelRadiance;
class ShadowMaps;

class DvsVoxelLighting {
public:
    /** memoryTag prefixes the scratch volume and uniforms (e.g. ctx.tag("lighting")). */
    DvsVoxelLighting(vk::Context& ctx, Voxelizer& voxelizer, VoxelRadiance& radiance,
                     ShadowMaps& shadows, const DvsSettings& settings,
                     const std::string& memoryTag);
    DvsVoxelLighting(const DvsVoxelLighting&) = delete;
    DvsVoxelLighting& operator=(const DvsVoxelLighting&) = delete;

    /** L1: writes radiance.base() for every voxel (0 where empty). */
    void recordDirect(VkCommandBuffer cmd);
    /** G1: base += first bounce; needs radiance.filter() after recordDirect(). */
    void recordBounce(VkCommandBuffer cmd);
    /** Frees the G1 scratch volume (after the set-up submission finished). */
    void releaseScratch() { m_scratch = vk::Image(); }

private:
    vk::Context& m_ctx;
    Voxelizer& m_voxelizer;
    VoxelRadiance& m_radiance;
    ShadowMaps& m_shadows;
    DvsSettings m_settings;
    vk::Sampler m_nearest;

    vk::DescriptorSetLayout m_directSetLayout;
    vk::DescriptorSet m_directSet;
    vk::PipelineLayout m_directLayout;
    vk::ComputePipeline m_direct;

    vk::Image m_scratch;
    vk::Buffer m_bounceUniforms;
    vk::DescriptorSetLayout m_bounceSetLayout;
    vk::DescriptorSet m_bounceSet;
    vk::PipelineLayout m_bounceLayout;
    vk::ComputePipeline m_bounce;
};

}  // namespace gilab
