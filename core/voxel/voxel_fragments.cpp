#include "core/voxel/voxel_fragments.h"

#include <string>

#include <glm/gtc/packing.hpp>

#include "core/util/error.h"
#include "core/vk/context.h"

namespace gilab {
namespace {

constexpr VkBufferUsageFlags kStorage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT |
                                        VK_BUFFER_USAGE_TRANSFER_DST_BIT |
                                        VK_BUFFER_USAGE_TRANSFER_SRC_BIT;

void checkRange(vk::Context& ctx, VkDeviceSize bytes, const std::string& what) {
    const VkDeviceSize range = ctx.properties().limits.maxStorageBufferRange;
    if (bytes > range) {
        throw DeviceLimitError("voxel fragment lists: " + what + " needs " +
                               std::to_string(bytes >> 20) +
                               " MiB in one binding, above the device's maxStorageBufferRange (" +
                               std::to_string(range >> 20) + " MiB); use a lower voxel resolution");
    }
}

}  // namespace

glm::vec3 fragmentNormal(const GpuVoxelFragment& f) {
    glm::vec2 e = glm::unpackSnorm2x16(f.normalOct);
    glm::vec3 n(e.x, e.y, 1.0f - std::abs(e.x) - std::abs(e.y));
    if (n.z < 0.0f) {  // octahedral unwrap
        const glm::vec2 w((1.0f - std::abs(e.y)) * (e.x >= 0.0f ? 1.0f : -1.0f),
                          (1.0f - std::abs(e.x)) * (e.y >= 0.0f ? 1.0f : -1.0f));
        n.x = w.x;
        n.y = w.y;
    }
    const float len = glm::length(n);
    return len > 0.0f ? n / len : glm::vec3(0.0f);
}

glm::vec3 fragmentAlbedo(const GpuVoxelFragment& f) {
    const glm::vec2 rg = glm::unpackHalf2x16(f.albedoLo);
    return glm::vec3(rg, glm::unpackHalf2x16(f.albedoHi).x);
}

VoxelFragmentLists::VoxelFragmentLists(vk::Context& ctx, const VoxelGrid& grid, uint32_t capacity)
    : m_ctx(ctx), m_grid(grid) {
    const VkDeviceSize headBytes = VkDeviceSize(grid.voxelCount()) * 4;
    checkRange(ctx, headBytes,
               "the voxel buffer of " + std::to_string(grid.resolution()) + "^3 list heads");
    m_heads =
        vk::Buffer(ctx, headBytes, kStorage, vk::MemoryUsage::DeviceLocal, "voxel/fragment_heads");
    m_counter =
        vk::Buffer(ctx, 8, kStorage, vk::MemoryUsage::DeviceLocal, "voxel/fragment_counter");
    const VkShaderStageFlags fs = VK_SHADER_STAGE_FRAGMENT_BIT;
    m_layout = vk::DescriptorSetLayout(ctx,
                                       {{0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, fs},
                                        {1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, fs},
                                        {2, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, fs}},
                                       "voxel/fragment_lists");
    m_set = vk::DescriptorSet(ctx, m_layout, 0, "voxel/fragment_lists");
    m_set.writeBuffer(0, m_heads);
    m_set.writeBuffer(2, m_counter);
    allocateFragments(capacity);
}

void VoxelFragmentLists::allocateFragments(uint32_t capacity) {
    if (capacity == 0) throw Error("voxel fragment lists: capacity must be > 0");
    const VkDeviceSize bytes = VkDeviceSize(capacity) * sizeof(GpuVoxelFragment);
    checkRange(m_ctx, bytes, std::to_string(capacity) + " fragments");
    m_fragments =
        vk::Buffer(m_ctx, bytes, kStorage, vk::MemoryUsage::DeviceLocal, "voxel/fragments");
    m_capacity = capacity;
    m_set.writeBuffer(1, m_fragments);
}

void VoxelFragmentLists::recordClear(VkCommandBuffer cmd) {
    vkCmdFillBuffer(cmd, m_heads.handle(), 0, VK_WHOLE_SIZE, kVoxelListEnd);
    const uint32_t counter[2] = {0u, m_capacity};
    vkCmdUpdateBuffer(cmd, m_counter.handle(), 0, sizeof(counter), counter);
}

uint32_t VoxelFragmentLists::written() {
    uint32_t count = 0;
    m_counter.download(&count, 4);
    return count;
}

void VoxelFragmentLists::grow(uint32_t capacity) {
    // run() waits for its submission, so the old buffer is idle
    allocateFragments(capacity);
}

std::vector<GpuVoxelFragment> VoxelFragmentLists::readFragments(uint32_t count) {
    if (count > m_capacity) {
        throw DeviceLimitError("voxel fragment lists: " + std::to_string(count) +
                               " fragments requested, only " + std::to_string(m_capacity) +
                               " stored");
    }
    return m_fragments.downloadVector<GpuVoxelFragment>(count);
}

void VoxelFragmentLists::releaseFragments() {
    m_fragments = vk::Buffer();
    m_capacity = 0;
}

}  // namespace gilab
