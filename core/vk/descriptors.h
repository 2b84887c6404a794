#pragma once
/**
 * Descriptor set layouts and sets. Each DescriptorSet owns a small pool sized for its layout,
 * so sets are independent RAII objects (fine at our scale).
 */
#include <cstdint>
#include <string>
#include <vector>

#include <vulkan/vulkan.h>

#include "core/vk/handle.h"

namespace gilab::vk {

class Buffer;
class Context;

struct DescriptorBinding {
    uint32_t binding = 0;
    VkDescriptorType type = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    uint32_t count = 1;  // upper bound when variableCount
    VkShaderStageFlags stages = VK_SHADER_STAGE_ALL;
    bool variableCount = false;  // last binding only; also partially bound
};

class DescriptorSetLayout {
public:
    DescriptorSetLayout() = default;
    DescriptorSetLayout(Context& ctx, std::vector<DescriptorBinding> bindings,
                        const std::string& name = {});
    VkDescriptorSetLayout handle() const { return m_layout.handle(); }
    const std::vector<DescriptorBinding>& bindings() const { return m_bindings; }
    bool hasVariableCount() const;

private:
    DescriptorSetLayoutHandle m_layout;
    std::vector<DescriptorBinding> m_bindings;
};

class DescriptorSet {
public:
    DescriptorSet() = default;
    /** variableCount: descriptors in the variable-count binding (0 = its declared count). */
    DescriptorSet(Context& ctx, const DescriptorSetLayout& layout, uint32_t variableCount = 0,
                  const std::string& name = {});
    VkDescriptorSet handle() const { return m_set; }

    /** Storage buffer, or uniform buffer when the binding is declared as one. */
    void writeBuffer(uint32_t binding, const Buffer& buffer, uint32_t arrayElement = 0);
    void writeUniformBuffer(uint32_t binding, const Buffer& buffer, uint32_t arrayElement = 0);
    /** Storage image in layout GENERAL. */
    void writeStorageImage(uint32_t binding, VkImageView view, uint32_t arrayElement = 0);
    /** Combined image sampler. */
    void writeSampledImage(uint32_t binding, VkImageView view, VkSampler sampler,
                           VkImageLayout layout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                           uint32_t arrayElement = 0);

private:
    VkDescriptorType bindingType(uint32_t binding) const;

    VkDevice m_device = VK_NULL_HANDLE;
    DescriptorPoolHandle m_pool;
    VkDescriptorSet m_set = VK_NULL_HANDLE;
    std::vector<DescriptorBinding> m_bindings;
};

}  // namespace gilab::vk
