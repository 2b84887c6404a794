#include "pixel_clusters.h"

#include "core/passes/gbuffer.h"
#include "core/util/error.h"
#include "core/vk/barrier.h"
#include "core/vk/context.h"
#include "scene_topology.h"

namespace gilab::topo {
PixelClusters::PixelClusters(vk::Context& ctx, GBuffer& gbuffer, const SceneTopology& t,
                             const std::string& tag)
    : m_width(gbuffer.width), m_height(gbuffer.height), m_grid(t.grid) {
    const VkDeviceSize bytes = VkDeviceSize(t.voxelCluster.size()) * 4;
    const VkDeviceSize range = ctx.properties().limits.maxStorageBufferRange;
    if (bytes > range)
        throw DeviceLimitError(tag + ": the " + std::to_string(t.dims.nx) +
                               "^3 cluster grid needs " + std::to_string(bytes >> 20) +
                               " MiB in one binding, above the device's maxStorageBufferRange (" +
                               std::to_string(range >> 20) + " MiB); lower voxel_resolution");
    m_voxelClusters = vk::Buffer(
        ctx, bytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
        vk::MemoryUsage::DeviceLocal, tag + "/voxel_clusters");
    m_voxelClusters.uploadVector(t.voxelCluster);
    auto frameImage = [&](VkFormat format, const std::string& name) {
        return vk::Image(ctx, vk::imageDesc2D(m_width, m_height, format, VK_IMAGE_USAGE_STORAGE_BIT,
                                              tag + name));
    };
    m_clusters = frameImage(VK_FORMAT_R32_UINT, "/pixel_clusters");
    m_debug = frameImage(VK_FORMAT_R32G32B32A32_SFLOAT, "/cluster_view");
    ctx.submitAndWait([&](VkCommandBuffer cmd) {
        m_clusters.transition(cmd, VK_IMAGE_LAYOUT_GENERAL);
        m_debug.transition(cmd, VK_IMAGE_LAYOUT_GENERAL);
    });
    const VkShaderStageFlags cs = VK_SHADER_STAGE_COMPUTE_BIT;
    const VkDescriptorType img = VK_DESCRIPTOR_TYPE_STORAGE_IMAGE;
    m_setLayout = vk::DescriptorSetLayout(ctx,
                                          {{0, img, 1, cs},
                                           {1, img, 1, cs},
                                           {2, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, cs},
                                           {3, img, 1, cs},
                                           {4, img, 1, cs}},
                                          tag + "/pixel_clusters");
    m_set = vk::DescriptorSet(ctx, m_setLayout, 0, tag + "/pixel_clusters");
    m_set.writeStorageImage(0, gbuffer.position.view());
    m_set.writeStorageImage(1, gbuffer.normal.view());
    m_set.writeBuffer(2, m_voxelClusters);
    m_set.writeStorageImage(3, m_clusters.view());
    m_set.writeStorageImage(4, m_debug.view());
    m_layout = vk::PipelineLayout(ctx, {m_setLayout.handle()}, sizeof(GpuVoxelGrid) + 16);
    m_pipeline = vk::ComputePipeline(ctx, "topovpl/pixel_cluster.comp", m_layout);
}

void PixelClusters::record(VkCommandBuffer cmd, const glm::vec3& eye) {
    m_pipeline.bind(cmd);
    VkDescriptorSet set = m_set.handle();
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, m_layout.handle(), 0, 1, &set, 0,
                            nullptr);
    const struct {
        GpuVoxelGrid grid;
        glm::vec4 eye;
    } push{m_grid.gpu(), glm::vec4(eye, 1.0f)};
    m_layout.push(cmd, push);
    vk::dispatch2D(cmd, m_width, m_height);
    vk::memoryBarrier(cmd);
}

}  // namespace gilab::topo
