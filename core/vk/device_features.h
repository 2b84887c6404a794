#pragma once
/**
 * Internal to Context: what a physical device supports, which of it gilab requires, and the
 * feature chain enabled at device creation. Required features are listed in one place
 * (device_features.cpp) so rejections name exactly what is missing.
 */
#include <string>
#include <vector>

#include <vulkan/vulkan.h>

namespace gilab::vk {

struct DeviceSupport {
    std::string name;
    std::string typeName;
    int typeRank = 9;  // 0 discrete, 1 integrated, 2 virtual, 3 cpu, 4 other
    VkPhysicalDeviceProperties properties{};
    std::string driverName;
    std::string driverInfo;
    uint32_t queueFamily = UINT32_MAX;
    uint32_t timestampValidBits = 0;
    std::vector<std::string> extensions;
    VkPhysicalDeviceFeatures core{};
    VkPhysicalDeviceVulkan11Features v11{};
    VkPhysicalDeviceVulkan12Features v12{};
    VkPhysicalDeviceVulkan13Features v13{};
    VkPhysicalDeviceShaderAtomicFloatFeaturesEXT atomicFloat{};
    std::vector<std::string> missing;  // empty = usable

    bool hasExtension(const std::string& name) const;
};

/** The feature chain passed to vkCreateDevice. Non-copyable: the pNext chain points inside. */
struct EnabledFeatures {
    EnabledFeatures() = default;
    EnabledFeatures(const EnabledFeatures&) = delete;
    EnabledFeatures& operator=(const EnabledFeatures&) = delete;

    VkPhysicalDeviceFeatures2 features2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
    VkPhysicalDeviceVulkan11Features v11{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_1_FEATURES};
    VkPhysicalDeviceVulkan12Features v12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
    VkPhysicalDeviceVulkan13Features v13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
    VkPhysicalDeviceShaderAtomicFloatFeaturesEXT atomicFloat{
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SHADER_ATOMIC_FLOAT_FEATURES_EXT};
    std::vector<std::string> extensions;
    bool floatAtomics = false;
    bool conservativeRaster = false;
    bool descriptorIndexing = false;
};

std::string deviceTypeName(VkPhysicalDeviceType type);
DeviceSupport queryDeviceSupport(VkPhysicalDevice device);
/** Fills `out` with required + supported optional features and links its pNext chain. */
void chooseFeatures(const DeviceSupport& support, EnabledFeatures& out);

}  // namespace gilab::vk
