#include "core/vk/descriptors.h"

#include <algorithm>
#include <map>

#include "core/util/error.h"
#include "core/vk/buffer.h"
#include "core/vk/check.h"
#include "core/vk/context.h"

namespace gilab::vk {

DescriptorSetLayout::DescriptorSetLayout(Context& ctx, std::vector<DescriptorBinding> bindings,
                                         const std::string& name)
    : m_bindings(std::move(bindings)) {
    std::vector<VkDescriptorSetLayoutBinding> vkBindings;
    std::vector<VkDescriptorBindingFlags> flags;
    bool anyFlags = false;
    uint32_t maxBinding = 0;
    for (const auto& b : m_bindings)
        maxBinding = std::max(maxBinding, b.binding);
    for (const auto& b : m_bindings) {
        VkDescriptorSetLayoutBinding vb{};
        vb.binding = b.binding;
        vb.descriptorType = b.type;
        vb.descriptorCount = b.count;
        vb.stageFlags = b.stages;
        vkBindings.push_back(vb);
        VkDescriptorBindingFlags f = 0;
        if (b.variableCount) {
            if (!ctx.hasDescriptorIndexing()) {
                throw Error("descriptor set layout '" + name + "': binding " +
                            std::to_string(b.binding) +
                            " wants a variable descriptor count, "
                            "but " +
                            ctx.deviceName() + " lacks descriptor indexing");
            }
            if (b.binding != maxBinding) {
                throw Error("descriptor set layout '" + name +
                            "': only the highest binding may have a variable count");
            }
            f = VK_DESCRIPTOR_BINDING_VARIABLE_DESCRIPTOR_COUNT_BIT |
                VK_DESCRIPTOR_BINDING_PARTIALLY_BOUND_BIT;
            anyFlags = true;
        }
        flags.push_back(f);
    }
    VkDescriptorSetLayoutBindingFlagsCreateInfo flagsInfo{
        VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_BINDING_FLAGS_CREATE_INFO};
    flagsInfo.bindingCount = uint32_t(flags.size());
    flagsInfo.pBindingFlags = flags.data();
    VkDescriptorSetLayoutCreateInfo info{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
    info.pNext = anyFlags ? &flagsInfo : nullptr;
    info.bindingCount = uint32_t(vkBindings.size());
    info.pBindings = vkBindings.data();
    VkDescriptorSetLayout layout = VK_NULL_HANDLE;
    VK_CHECK(vkCreateDescriptorSetLayout(ctx.device(), &info, nullptr, &layout));
    m_layout = DescriptorSetLayoutHandle(ctx.device(), layout);
    ctx.setDebugName(VK_OBJECT_TYPE_DESCRIPTOR_SET_LAYOUT, uint64_t(layout), name);
}

bool DescriptorSetLayout::hasVariableCount() const {
    for (const auto& b : m_bindings) {
        if (b.variableCount) return true;
    }
    return false;
}

DescriptorSet::DescriptorSet(Context& ctx, const DescriptorSetLayout& layout,
                             uint32_t variableCount, const std::string& name)
    : m_device(ctx.device()), m_bindings(layout.bindings()) {
    std::map<VkDescriptorType, uint32_t> counts;
    uint32_t variable = 0;
    for (const auto& b : m_bindings) {
        uint32_t n = b.count;
        if (b.variableCount) {
            variable = variableCount == 0 ? b.count : std::min(variableCount, b.count);
            n = variable;
        }
        counts[b.type] += std::max(n, 1u);
    }
    std::vector<VkDescriptorPoolSize> sizes;
    for (auto [type, n] : counts)
        sizes.push_back({type, n});
    if (sizes.empty()) sizes.push_back({VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1});
    VkDescriptorPoolCreateInfo poolInfo{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
    poolInfo.maxSets = 1;
    poolInfo.poolSizeCount = uint32_t(sizes.size());
    poolInfo.pPoolSizes = sizes.data();
    VkDescriptorPool pool = VK_NULL_HANDLE;
    VK_CHECK(vkCreateDescriptorPool(m_device, &poolInfo, nullptr, &pool));
    m_pool = DescriptorPoolHandle(m_device, pool);

    VkDescriptorSetLayout vkLayout = layout.handle();
    VkDescriptorSetVariableDescriptorCountAllocateInfo variableInfo{
        VK_STRUCTURE_TYPE_DESCRIPTOR_SET_VARIABLE_DESCRIPTOR_COUNT_ALLOCATE_INFO};
    variableInfo.descriptorSetCount = 1;
    variableInfo.pDescriptorCounts = &variable;
    VkDescriptorSetAllocateInfo alloc{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
    alloc.pNext = layout.hasVariableCount() ? &variableInfo : nullptr;
    alloc.descriptorPool = pool;
    alloc.descriptorSetCount = 1;
    alloc.pSetLayouts = &vkLayout;
    VK_CHECK(vkAllocateDescriptorSets(m_device, &alloc, &m_set));
    ctx.setDebugName(VK_OBJECT_TYPE_DESCRIPTOR_POOL, uint64_t(pool), name);
    ctx.setDebugName(VK_OBJECT_TYPE_DESCRIPTOR_SET, uint64_t(m_set), name);
}

VkDescriptorType DescriptorSet::bindingType(uint32_t binding) const {
    for (const auto& b : m_bindings) {
        if (b.binding == binding) return b.type;
    }
    throw Error("descriptor set has no binding " + std::to_string(binding));
}

void DescriptorSet::writeBuffer(uint32_t binding, const Buffer& buffer, uint32_t arrayElement) {
    VkDescriptorBufferInfo info = buffer.descriptor();
    VkWriteDescriptorSet write{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    write.dstSet = m_set;
    write.dstBinding = binding;
    write.dstArrayElement = arrayElement;
    write.descriptorCount = 1;
    write.descriptorType = bindingType(binding);
    write.pBufferInfo = &info;
    vkUpdateDescriptorSets(m_device, 1, &write, 0, nullptr);
}

void DescriptorSet::writeUniformBuffer(uint32_t binding, const Buffer& buffer,
                                       uint32_t arrayElement) {
    writeBuffer(binding, buffer, arrayElement);
}

void DescriptorSet::writeStorageImage(uint32_t binding, VkImageView view, uint32_t arrayElement) {
    VkDescriptorImageInfo info{VK_NULL_HANDLE, view, VK_IMAGE_LAYOUT_GENERAL};
    VkWriteDescriptorSet write{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    write.dstSet = m_set;
    write.dstBinding = binding;
    write.dstArrayElement = arrayElement;
    write.descriptorCount = 1;
    write.descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_IMAGE;
    write.pImageInfo = &info;
    vkUpdateDescriptorSets(m_device, 1, &write, 0, nullptr);
}

void DescriptorSet::writeSampledImage(uint32_t binding, VkImageView view, VkSampler sampler,
                                      VkImageLayout layout, uint32_t arrayElement) {
    VkDescriptorImageInfo info{sampler, view, layout};
    VkWriteDescriptorSet write{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    write.dstSet = m_set;
    write.dstBinding = binding;
    write.dstArrayElement = arrayElement;
    write.descriptorCount = 1;
    write.descriptorType = bindingType(binding);  // combined image sampler or sampled image
    write.pImageInfo = &info;
    vkUpdateDescriptorSets(m_device, 1, &write, 0, nullptr);
}

}  // namespace gilab::vk
