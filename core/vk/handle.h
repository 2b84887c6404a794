#pragma once
/**
 * Move-only RAII for plain device-owned handles:
 *   using PipelineHandle = DeviceHandle<VkPipeline, vkDestroyPipeline>;
 * Destroy has the signature void(VkDevice, T, const VkAllocationCallbacks*).
 */
#include <utility>

#include <vulkan/vulkan.h>

namespace gilab::vk {

template <class T, auto Destroy>
class DeviceHandle {
public:
    DeviceHandle() = default;
    DeviceHandle(VkDevice device, T handle) : m_device(device), m_handle(handle) {}
    ~DeviceHandle() { reset(); }

    DeviceHandle(const DeviceHandle&) = delete;
    DeviceHandle& operator=(const DeviceHandle&) = delete;
    DeviceHandle(DeviceHandle&& other) noexcept
        : m_device(std::exchange(other.m_device, VK_NULL_HANDLE)),
          m_handle(std::exchange(other.m_handle, VK_NULL_HANDLE)) {}
    DeviceHandle& operator=(DeviceHandle&& other) noexcept {
        if (this != &other) {
            reset();
            m_device = std::exchange(other.m_device, VK_NULL_HANDLE);
            m_handle = std::exchange(other.m_handle, VK_NULL_HANDLE);
        }
        return *this;
    }

    T handle() const { return m_handle; }
    T get() const { return m_handle; }
    VkDevice device() const { return m_device; }
    explicit operator bool() const { return m_handle != VK_NULL_HANDLE; }

    /** Gives up ownership without destroying. */
    T release() {
        m_device = VK_NULL_HANDLE;
        return std::exchange(m_handle, VK_NULL_HANDLE);
    }
    void reset() {
        if (m_handle != VK_NULL_HANDLE && m_device != VK_NULL_HANDLE) {
            Destroy(m_device, m_handle, nullptr);
        }
        m_handle = VK_NULL_HANDLE;
    }

private:
    VkDevice m_device = VK_NULL_HANDLE;
    T m_handle = VK_NULL_HANDLE;
};

using SamplerHandle = DeviceHandle<VkSampler, vkDestroySampler>;
using DescriptorSetLayoutHandle = DeviceHandle<VkDescriptorSetLayout, vkDestroyDescriptorSetLayout>;
using DescriptorPoolHandle = DeviceHandle<VkDescriptorPool, vkDestroyDescriptorPool>;
using PipelineLayoutHandle = DeviceHandle<VkPipelineLayout, vkDestroyPipelineLayout>;
using PipelineHandle = DeviceHandle<VkPipeline, vkDestroyPipeline>;
using ShaderModuleHandle = DeviceHandle<VkShaderModule, vkDestroyShaderModule>;
using CommandPoolHandle = DeviceHandle<VkCommandPool, vkDestroyCommandPool>;
using QueryPoolHandle = DeviceHandle<VkQueryPool, vkDestroyQueryPool>;
using FenceHandle = DeviceHandle<VkFence, vkDestroyFence>;
using SemaphoreHandle = DeviceHandle<VkSemaphore, vkDestroySemaphore>;
using ImageViewHandle = DeviceHandle<VkImageView, vkDestroyImageView>;

}  // namespace gilab::vk
