#include "core/voxel/voxel_compaction.h"

#include <algorithm>
#include <string>

#include "core/util/error.h"
#include "core/vk/barrier.h"
#include "core/vk/context.h"

namespace gilab {
namespace {

constexpr uint32_t kBlock = 256 * 16;  // VOXEL_COMPACT_BLOCK
constexpr VkBufferUsageFlags kStorage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT |
                                        VK_BUFFER_USAGE_TRANSFER_DST_BIT |
                                        VK_BUFFER_USAGE_TRANSFER_SRC_BIT;

}  // namespace

VoxelCompaction::VoxelCompaction(vk::Context& ctx, const VoxelGrid& grid, const vk::Buffer& heads)
    : m_ctx(ctx), m_grid(grid), m_heads(heads) {
    const uint64_t voxels = grid.voxelCount();
    m_blockCount = uint32_t((voxels + kBlock - 1) / kBlock);
    m_blocks = vk::Buffer(ctx, VkDeviceSize(m_blockCount + 1) * 4, kStorage,
                          vk::MemoryUsage::DeviceLocal, "voxel/compact_blocks");
    m_voxelIndex = vk::Buffer(ctx, VkDeviceSize(voxels) * 4, kStorage, vk::MemoryUsage::DeviceLocal,
                              "voxel/voxel_index");
    const VkShaderStageFlags cs = VK_SHADER_STAGE_COMPUTE_BIT;
    m_scanLayout = vk::DescriptorSetLayout(ctx,
                                           {{0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, cs},
                                            {1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, cs}},
                                           "voxel/compact_scan");
    m_scanSet = vk::DescriptorSet(ctx, m_scanLayout, 0, "voxel/compact_scan");
    m_scanSet.writeBuffer(0, heads);
    m_scanSet.writeBuffer(1, m_blocks);
    m_fillLayout = vk::DescriptorSetLayout(ctx,
                                           {{0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, cs},
                                            {1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, cs},
                                            {2, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, cs},
                                            {3, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, cs},
                                            {4, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, cs}},
                                           "voxel/compact_fill");
    m_scanPipelineLayout = vk::PipelineLayout(ctx, {m_scanLayout.handle()}, sizeof(Push));
    m_fillPipelineLayout = vk::PipelineLayout(ctx, {m_fillLayout.handle()}, sizeof(Push));
    m_count = vk::ComputePipeline(ctx, "common/voxel_compact_count.comp", m_scanPipelineLayout);
    m_scan = vk::ComputePipeline(ctx, "common/voxel_compact_scan.comp", m_scanPipelineLayout);
    m_fill = vk::ComputePipeline(ctx, "common/voxel_compact_fill.comp", m_fillPipelineLayout);
}

void VoxelCompaction::bind(VkCommandBuffer cmd, const vk::PipelineLayout& layout,
                           const vk::DescriptorSet& set) const {
    const Push push{uint32_t(m_grid.voxelCount()), m_blockCount};
    VkDescriptorSet handle = set.handle();
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, layout.handle(), 0, 1, &handle, 0,
                            nullptr);
    layout.push(cmd, push);
}

void VoxelCompaction::recordScan(VkCommandBuffer cmd) {
    bind(cmd, m_scanPipelineLayout, m_scanSet);
    m_count.bind(cmd);
    vkCmdDispatch(cmd, m_blockCount, 1, 1);
    vk::memoryBarrier(cmd);
    m_scan.bind(cmd);
    vkCmdDispatch(cmd, 1, 1, 1);
    vk::memoryBarrier(cmd);
}

uint32_t VoxelCompaction::readOccupied() {
    m_blocks.download(&m_occupied, 4, VkDeviceSize(m_blockCount) * 4);
    return m_occupied;
}

void VoxelCompaction::recordFill(VkCommandBuffer cmd, uint32_t occupied) {
    m_occupied = occupied;
    const VkDeviceSize bytes = VkDeviceSize(std::max(occupied, 1u)) * 4;
    m_fragmentIndex =
        vk::Buffer(m_ctx, bytes, kStorage, vk::MemoryUsage::DeviceLocal, "voxel/fragment_index");
    m_hashedPosition =
        vk::Buffer(m_ctx, bytes, kStorage, vk::MemoryUsage::DeviceLocal, "voxel/hashed_position");
    m_fillSet = vk::DescriptorSet(m_ctx, m_fillLayout, 0, "voxel/compact_fill");
    m_fillSet.writeBuffer(0, m_heads);
    m_fillSet.writeBuffer(1, m_blocks);
    m_fillSet.writeBuffer(2, m_fragmentIndex);
    m_fillSet.writeBuffer(3, m_hashedPosition);
    m_fillSet.writeBuffer(4, m_voxelIndex);
    bind(cmd, m_fillPipelineLayout, m_fillSet);
    m_fill.bind(cmd);
    vkCmdDispatch(cmd, m_blockCount, 1, 1);
    vk::memoryBarrier(cmd);
}

}  // namespace gilab
