#include "core/vk/buffer.h"

#include <algorithm>
#include <utility>

#include "core/util/error.h"
#include "core/vk/barrier.h"
#include "core/vk/check.h"
#include "core/vk/context.h"

namespace gilab::vk {

Buffer::Buffer(Context& ctx, VkDeviceSize size, VkBufferUsageFlags usage, MemoryUsage mem,
               std::string name)
    : m_ctx(&ctx), m_size(std::max<VkDeviceSize>(size, 16)), m_usage(mem), m_name(std::move(name)) {
    VkDevice device = ctx.device();
    usage |= VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
    VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    info.size = m_size;
    info.usage = usage;
    info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    VK_CHECK(vkCreateBuffer(device, &info, nullptr, &m_buffer));

    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(device, m_buffer, &req);
    uint32_t type = UINT32_MAX;
    if (mem == MemoryUsage::DeviceLocal) {
        type = ctx.findMemoryType(req.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
    } else {
        VkMemoryPropertyFlags host = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT;
        VkMemoryPropertyFlags preferred =
            host | (mem == MemoryUsage::Readback ? VK_MEMORY_PROPERTY_HOST_CACHED_BIT
                                                 : VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
        type = ctx.tryFindMemoryType(req.memoryTypeBits,
                                     preferred | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
        if (type == UINT32_MAX) type = ctx.tryFindMemoryType(req.memoryTypeBits, preferred);
        if (type == UINT32_MAX) type = ctx.findMemoryType(req.memoryTypeBits, host);
    }
    VkPhysicalDeviceMemoryProperties props;
    vkGetPhysicalDeviceMemoryProperties(ctx.physicalDevice(), &props);
    m_coherent =
        (props.memoryTypes[type].propertyFlags & VK_MEMORY_PROPERTY_HOST_COHERENT_BIT) != 0;

    VkMemoryAllocateFlagsInfo flags{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO};
    VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    alloc.allocationSize = req.size;
    alloc.memoryTypeIndex = type;
    if (usage & VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT) {
        flags.flags = VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT;
        alloc.pNext = &flags;
    }
    VkResult result = vkAllocateMemory(device, &alloc, nullptr, &m_memory);
    const bool allocated = result == VK_SUCCESS;
    if (allocated) result = vkBindBufferMemory(device, m_buffer, m_memory, 0);
    if (result != VK_SUCCESS) {  // allocation or binding refused: release both, name the buffer
        const std::string step = allocated ? "binding" : "allocating";
        if (allocated) vkFreeMemory(device, m_memory, nullptr);
        vkDestroyBuffer(device, m_buffer, nullptr);
        m_memory = VK_NULL_HANDLE;
        m_buffer = VK_NULL_HANDLE;
        if (isOutOfMemory(result)) throw OutOfMemoryError(step, "buffer", m_name, req.size, result);
        throw Error(step + " " + std::to_string(req.size) + " bytes for buffer '" + m_name +
                    "' failed: " + resultName(result));
    }
    m_allocSize = req.size;
    if (mem != MemoryUsage::DeviceLocal) {
        VK_CHECK(vkMapMemory(device, m_memory, 0, VK_WHOLE_SIZE, 0, &m_mapped));
    }
    ctx.setDebugName(VK_OBJECT_TYPE_BUFFER, uint64_t(m_buffer), m_name);
    ctx.setDebugName(VK_OBJECT_TYPE_DEVICE_MEMORY, uint64_t(m_memory), m_name);
    ctx.memory().add(m_name, m_allocSize);
}

Buffer::~Buffer() {
    destroy();
}

Buffer::Buffer(Buffer&& other) noexcept {
    *this = std::move(other);
}

Buffer& Buffer::operator=(Buffer&& other) noexcept {
    if (this != &other) {
        destroy();
        m_ctx = std::exchange(other.m_ctx, nullptr);
        m_buffer = std::exchange(other.m_buffer, VK_NULL_HANDLE);
        m_memory = std::exchange(other.m_memory, VK_NULL_HANDLE);
        m_size = std::exchange(other.m_size, 0);
        m_allocSize = std::exchange(other.m_allocSize, 0);
        m_coherent = other.m_coherent;
        m_usage = other.m_usage;
        m_mapped = std::exchange(other.m_mapped, nullptr);
        m_name = std::move(other.m_name);
    }
    return *this;
}

void Buffer::destroy() {
    if (!m_ctx) return;
    VkDevice device = m_ctx->device();
    if (m_mapped) vkUnmapMemory(device, m_memory);
    if (m_buffer) vkDestroyBuffer(device, m_buffer, nullptr);
    if (m_memory) {
        vkFreeMemory(device, m_memory, nullptr);
        m_ctx->memory().remove(m_name, m_allocSize);
    }
    m_ctx = nullptr;
    m_buffer = VK_NULL_HANDLE;
    m_memory = VK_NULL_HANDLE;
    m_mapped = nullptr;
}

namespace {
void checkRange(const std::string& name, VkDeviceSize size, VkDeviceSize bytes, VkDeviceSize offset,
                const char* what) {
    if (offset + bytes > size) {
        throw Error(std::string(what) + " of " + std::to_string(bytes) + " bytes at offset " +
                    std::to_string(offset) + " exceeds buffer '" + name + "' of " +
                    std::to_string(size) + " bytes");
    }
}
}  // namespace

void Buffer::upload(const void* data, VkDeviceSize bytes, VkDeviceSize offset) {
    if (!m_ctx) throw Error("upload into an empty Buffer");
    checkRange(m_name, m_size, bytes, offset, "upload");
    if (bytes == 0) return;
    if (m_mapped) {
        std::memcpy(static_cast<char*>(m_mapped) + offset, data, bytes);
        if (!m_coherent) {
            VkMappedMemoryRange range{VK_STRUCTURE_TYPE_MAPPED_MEMORY_RANGE};
            range.memory = m_memory;
            range.size = VK_WHOLE_SIZE;
            VK_CHECK(vkFlushMappedMemoryRanges(m_ctx->device(), 1, &range));
        }
        return;
    }
    Buffer staging(*m_ctx, bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, MemoryUsage::Upload,
                   "staging/" + m_name);
    staging.upload(data, bytes);
    m_ctx->submitAndWait([&](VkCommandBuffer cmd) {
        VkBufferCopy copy{0, offset, bytes};
        memoryBarrier(cmd);  // earlier submissions' accesses before the copy writes
        vkCmdCopyBuffer(cmd, staging.handle(), m_buffer, 1, &copy);
        memoryBarrier(cmd);  // the copy before anything submitted later
    });
}

void Buffer::download(void* data, VkDeviceSize bytes, VkDeviceSize offset) {
    if (!m_ctx) throw Error("download from an empty Buffer");
    checkRange(m_name, m_size, bytes, offset, "download");
    if (bytes == 0) return;
    if (m_mapped) {
        if (!m_coherent) {
            VkMappedMemoryRange range{VK_STRUCTURE_TYPE_MAPPED_MEMORY_RANGE};
            range.memory = m_memory;
            range.size = VK_WHOLE_SIZE;
            VK_CHECK(vkInvalidateMappedMemoryRanges(m_ctx->device(), 1, &range));
        }
        std::memcpy(data, static_cast<const char*>(m_mapped) + offset, bytes);
        return;
    }
    Buffer staging(*m_ctx, bytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT, MemoryUsage::Readback,
                   "staging/" + m_name);
    m_ctx->submitAndWait([&](VkCommandBuffer cmd) {
        VkBufferCopy copy{offset, 0, bytes};
        memoryBarrier(cmd);
        vkCmdCopyBuffer(cmd, m_buffer, staging.handle(), 1, &copy);
        hostReadBarrier(cmd);
    });
    staging.download(data, bytes);
}

VkDeviceAddress Buffer::deviceAddress() const {
    VkBufferDeviceAddressInfo info{VK_STRUCTURE_TYPE_BUFFER_DEVICE_ADDRESS_INFO};
    info.buffer = m_buffer;
    return vkGetBufferDeviceAddress(m_ctx->device(), &info);
}

}  // namespace gilab::vk
