#include "core/vk/device_features.h"

#include <algorithm>

namespace gilab::vk {

bool DeviceSupport::hasExtension(const std::string& ext) const {
    return std::find(extensions.begin(), extensions.end(), ext) != extensions.end();
}

std::string deviceTypeName(VkPhysicalDeviceType type) {
    switch (type) {
        case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU:
            return "discrete";
        case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU:
            return "integrated";
        case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU:
            return "virtual";
        case VK_PHYSICAL_DEVICE_TYPE_CPU:
            return "cpu";
        default:
            return "other";
    }
}

namespace {

int typeRank(VkPhysicalDeviceType type) {
    switch (type) {
        case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU:
            return 0;
        case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU:
            return 1;
        case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU:
            return 2;
        case VK_PHYSICAL_DEVICE_TYPE_CPU:
            return 3;
        default:
            return 4;
    }
}

// Required features: (struct, member). Each is checked, reported by name, and enabled.
#define GILAB_REQUIRED_FEATURES(X)                \
    X(core, geometryShader)                       \
    X(core, fragmentStoresAndAtomics)             \
    X(core, vertexPipelineStoresAndAtomics)       \
    X(core, imageCubeArray)                       \
    X(core, shaderStorageImageWriteWithoutFormat) \
    X(core, independentBlend)                     \
    X(core, depthClamp)                           \
    X(core, depthBiasClamp)                       \
    X(v12, scalarBlockLayout)                     \
    X(v12, hostQueryReset)                        \
    X(v13, dynamicRendering)                      \
    X(v13, synchronization2)

// Optional features: enabled when present.
#define GILAB_OPTIONAL_FEATURES(X)                     \
    X(core, shaderStorageImageReadWithoutFormat)       \
    X(core, shaderStorageImageExtendedFormats)         \
    X(core, fillModeNonSolid)                          \
    X(core, samplerAnisotropy)                         \
    X(core, multiDrawIndirect)                         \
    X(core, drawIndirectFirstInstance)                 \
    X(core, shaderInt64)                               \
    X(core, shaderImageGatherExtended)                 \
    X(core, shaderStorageBufferArrayDynamicIndexing)   \
    X(core, shaderSampledImageArrayDynamicIndexing)    \
    X(core, shaderStorageImageArrayDynamicIndexing)    \
    X(v11, multiview)                                  \
    X(v11, multiviewGeometryShader)                    \
    X(v11, shaderDrawParameters)                       \
    X(v12, runtimeDescriptorArray)                     \
    X(v12, shaderSampledImageArrayNonUniformIndexing)  \
    X(v12, shaderStorageBufferArrayNonUniformIndexing) \
    X(v12, shaderStorageImageArrayNonUniformIndexing)  \
    X(v12, descriptorBindingPartiallyBound)            \
    X(v12, descriptorBindingVariableDescriptorCount)   \
    X(v12, bufferDeviceAddress)                        \
    X(v12, timelineSemaphore)                          \
    X(v12, drawIndirectCount)                          \
    X(v12, shaderOutputLayer)                          \
    X(v12, shaderOutputViewportIndex)                  \
    X(v13, maintenance4)

}  // namespace

DeviceSupport queryDeviceSupport(VkPhysicalDevice device) {
    DeviceSupport s;
    VkPhysicalDeviceDriverProperties driver{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES};
    VkPhysicalDeviceProperties2 props2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2};
    vkGetPhysicalDeviceProperties(device, &s.properties);
    bool api13 = s.properties.apiVersion >= VK_API_VERSION_1_3;
    if (s.properties.apiVersion >= VK_API_VERSION_1_2) {
        props2.pNext = &driver;
        vkGetPhysicalDeviceProperties2(device, &props2);
        s.driverName = driver.driverName;
        s.driverInfo = driver.driverInfo;
    }
    s.name = s.properties.deviceName;
    s.typeName = deviceTypeName(s.properties.deviceType);
    s.typeRank = typeRank(s.properties.deviceType);

    uint32_t extCount = 0;
    vkEnumerateDeviceExtensionProperties(device, nullptr, &extCount, nullptr);
    std::vector<VkExtensionProperties> exts(extCount);
    vkEnumerateDeviceExtensionProperties(device, nullptr, &extCount, exts.data());
    for (const auto& e : exts)
        s.extensions.emplace_back(e.extensionName);

    uint32_t familyCount = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(device, &familyCount, nullptr);
    std::vector<VkQueueFamilyProperties> families(familyCount);
    vkGetPhysicalDeviceQueueFamilyProperties(device, &familyCount, families.data());
    const VkQueueFlags wanted = VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT;
    for (uint32_t i = 0; i < familyCount; ++i) {
        if ((families[i].queueFlags & wanted) == wanted) {
            s.queueFamily = i;
            s.timestampValidBits = families[i].timestampValidBits;
            break;
        }
    }

    if (!api13) {
        s.missing.push_back("Vulkan 1.3 (device reports " +
                            std::to_string(VK_API_VERSION_MAJOR(s.properties.apiVersion)) + "." +
                            std::to_string(VK_API_VERSION_MINOR(s.properties.apiVersion)) + ")");
        return s;
    }
    if (s.queueFamily == UINT32_MAX) s.missing.push_back("a graphics+compute queue");

    VkPhysicalDeviceFeatures2 f2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
    s.v11.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_1_FEATURES;
    s.v12.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES;
    s.v13.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES;
    s.atomicFloat.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SHADER_ATOMIC_FLOAT_FEATURES_EXT;
    f2.pNext = &s.v11;
    s.v11.pNext = &s.v12;
    s.v12.pNext = &s.v13;
    if (s.hasExtension(VK_EXT_SHADER_ATOMIC_FLOAT_EXTENSION_NAME)) s.v13.pNext = &s.atomicFloat;
    vkGetPhysicalDeviceFeatures2(device, &f2);
    s.core = f2.features;
    s.v11.pNext = s.v12.pNext = s.v13.pNext = nullptr;

#define GILAB_CHECK_FEATURE(group, member) \
    if (!s.group.member) s.missing.push_back(#member);
    GILAB_REQUIRED_FEATURES(GILAB_CHECK_FEATURE)
#undef GILAB_CHECK_FEATURE
    return s;
}

void chooseFeatures(const DeviceSupport& s, EnabledFeatures& out) {
    VkPhysicalDeviceFeatures& core = out.features2.features;
    auto& v11 = out.v11;
    auto& v12 = out.v12;
    auto& v13 = out.v13;
#define GILAB_ENABLE_FEATURE(group, member) group.member = s.group.member;
    GILAB_REQUIRED_FEATURES(GILAB_ENABLE_FEATURE)
    GILAB_OPTIONAL_FEATURES(GILAB_ENABLE_FEATURE)
#undef GILAB_ENABLE_FEATURE
    (void)v11;
    (void)v13;
    out.descriptorIndexing =
        v12.runtimeDescriptorArray && v12.shaderSampledImageArrayNonUniformIndexing &&
        v12.descriptorBindingPartiallyBound && v12.descriptorBindingVariableDescriptorCount;

    out.features2.pNext = &out.v11;
    out.v11.pNext = &out.v12;
    out.v12.pNext = &out.v13;
    out.v13.pNext = nullptr;
    if (s.hasExtension(VK_EXT_SHADER_ATOMIC_FLOAT_EXTENSION_NAME)) {
        out.extensions.push_back(VK_EXT_SHADER_ATOMIC_FLOAT_EXTENSION_NAME);
        auto& a = out.atomicFloat;
        a.shaderBufferFloat32Atomics = s.atomicFloat.shaderBufferFloat32Atomics;
        a.shaderBufferFloat32AtomicAdd = s.atomicFloat.shaderBufferFloat32AtomicAdd;
        a.shaderImageFloat32Atomics = s.atomicFloat.shaderImageFloat32Atomics;
        a.shaderImageFloat32AtomicAdd = s.atomicFloat.shaderImageFloat32AtomicAdd;
        out.floatAtomics = a.shaderBufferFloat32Atomics && a.shaderBufferFloat32AtomicAdd &&
                           a.shaderImageFloat32Atomics && a.shaderImageFloat32AtomicAdd;
        out.v13.pNext = &out.atomicFloat;
    }
    if (s.hasExtension(VK_EXT_CONSERVATIVE_RASTERIZATION_EXTENSION_NAME)) {
        out.extensions.push_back(VK_EXT_CONSERVATIVE_RASTERIZATION_EXTENSION_NAME);
        out.conservativeRaster = true;
    }
}

}  // namespace gilab::vk
