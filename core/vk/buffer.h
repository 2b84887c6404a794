#pragma once
/** A VkBuffer with its own VkDeviceMemory, accounted in Context::memory() under its name. */
#include <cstring>
#include <string>
#include <vector>

#include <vulkan/vulkan.h>

namespace gilab::vk {

class Context;

/** Upload/Readback are host-visible, coherent (or flushed/invalidated) and persistently mapped. */
enum class MemoryUsage { DeviceLocal, Upload, Readback };

class Buffer {
public:
    Buffer() = default;
    /** size 0 is rounded up to 16 bytes so empty scene arrays can still be bound. */
    Buffer(Context& ctx, VkDeviceSize size, VkBufferUsageFlags usage, MemoryUsage mem,
           std::string name);
    ~Buffer();
    Buffer(const Buffer&) = delete;
    Buffer& operator=(const Buffer&) = delete;
    Buffer(Buffer&& other) noexcept;
    Buffer& operator=(Buffer&& other) noexcept;

    VkBuffer handle() const { return m_buffer; }
    VkDeviceSize size() const { return m_size; }
    const std::string& name() const { return m_name; }
    /** Null for DeviceLocal. */
    void* mapped() const { return m_mapped; }
    MemoryUsage memoryUsage() const { return m_usage; }
    bool valid() const { return m_buffer != VK_NULL_HANDLE; }

    /** Mapped: memcpy (+flush). DeviceLocal: staging buffer + blocking copy. */
    void upload(const void* data, VkDeviceSize bytes, VkDeviceSize offset = 0);
    /** Mapped: invalidate + memcpy. DeviceLocal: blocking copy to a staging buffer. */
    void download(void* data, VkDeviceSize bytes, VkDeviceSize offset = 0);

    template <class T>
    void uploadVector(const std::vector<T>& v) {
        if (!v.empty()) upload(v.data(), v.size() * sizeof(T));
    }
    template <class T>
    std::vector<T> downloadVector(size_t count) {
        std::vector<T> out(count);
        if (count > 0) download(out.data(), count * sizeof(T));
        return out;
    }

    /** Whole buffer. */
    VkDescriptorBufferInfo descriptor() const { return {m_buffer, 0, VK_WHOLE_SIZE}; }
    VkDeviceAddress deviceAddress() const;

private:
    void destroy();

    Context* m_ctx = nullptr;
    VkBuffer m_buffer = VK_NULL_HANDLE;
    VkDeviceMemory m_memory = VK_NULL_HANDLE;
    VkDeviceSize m_size = 0;
    VkDeviceSize m_allocSize = 0;
    bool m_coherent = true;
    MemoryUsage m_usage = MemoryUsage::DeviceLocal;
    void* m_mapped = nullptr;
    std::string m_name;
};

}  // namespace gilab::vk
