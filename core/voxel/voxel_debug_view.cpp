#include "core/voxel/voxel_debug_view.h"

#include <glm/glm.hpp>

#include "core/util/error.h"
#include "core/vk/context.h"
#include "core/voxel/voxelizer.h"

namespace gilab {
namespace {

/** Mirrors VoxelDebugPush in shaders/common/voxel_debug_view.comp. */
struct VoxelDebugPush {
    glm::mat4 invViewProj;
    glm::vec4 eye;
    GpuVoxelGrid grid;
    glm::uvec4 modeSize;
};
static_assert(sizeof(VoxelDebugPush) == 128);

}  // namespace

VoxelDebugView::VoxelDebugView(vk::Context& ctx, Voxelizer& voxelizer, uint32_t width,
                               uint32_t height)
    : m_voxelizer(voxelizer) {
    if (width == 0 || height == 0) throw Error("VoxelDebugView: resolution must be non-zero");
    vk::ImageDesc desc;
    desc.format = VK_FORMAT_R32G32B32A32_SFLOAT;
    desc.width = width;
    desc.height = height;
    desc.usage = VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT;
    desc.name = "voxel/debug_view";
    m_image = vk::Image(ctx, desc);
    vk::SamplerDesc sd;
    sd.filter = VK_FILTER_NEAREST;
    sd.mipmap = VK_SAMPLER_MIPMAP_MODE_NEAREST;
    sd.name = "voxel/debug_view";
    m_sampler = vk::Sampler(ctx, sd);
    const VkShaderStageFlags cs = VK_SHADER_STAGE_COMPUTE_BIT;
    m_setLayout = vk::DescriptorSetLayout(ctx,
                                          {{0, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1, cs},
                                           {1, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1, cs},
                                           {2, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1, cs},
                                           {3, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1, cs}},
                                          "voxel/debug_view");
    m_set = vk::DescriptorSet(ctx, m_setLayout, 0, "voxel/debug_view");
    VoxelVolumes& v = voxelizer.volumes();
    m_set.writeSampledImage(0, v.albedoOpacity.view(), m_sampler.handle());
    m_set.writeSampledImage(1, v.normal.view(), m_sampler.handle());
    m_set.writeSampledImage(2, v.emission.view(), m_sampler.handle());
    m_set.writeStorageImage(3, m_image.view());
    m_layout = vk::PipelineLayout(ctx, {m_setLayout.handle()}, sizeof(VoxelDebugPush));
    m_pipeline = vk::ComputePipeline(ctx, "common/voxel_debug_view.comp", m_layout);
}

void VoxelDebugView::record(VkCommandBuffer cmd, const Camera& camera, VoxelDebugMode mode) {
    const uint32_t w = m_image.width(), h = m_image.height();
    m_image.transition(cmd, VK_IMAGE_LAYOUT_GENERAL);
    VoxelDebugPush push{};
    push.invViewProj = glm::inverse(camera.projection(float(w) / float(h)) * camera.view());
    push.eye = glm::vec4(camera.position, 1.0f);
    push.grid = m_voxelizer.grid().gpu();
    push.modeSize = glm::uvec4(uint32_t(mode), w, h, 0);
    m_pipeline.bind(cmd);
    VkDescriptorSet set = m_set.handle();
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, m_layout.handle(), 0, 1, &set, 0,
                            nullptr);
    m_layout.push(cmd, push);
    vk::dispatch2D(cmd, w, h);
    m_image.transition(cmd, VK_IMAGE_LAYOUT_GENERAL);
}

}  // namespace gilab
