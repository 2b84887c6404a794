#include "core/vk/context.h"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "core/util/error.h"
#include "core/vk/check.h"
#include "core/vk/device_features.h"

namespace gilab::vk {
namespace {

constexpr const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";

VKAPI_ATTR VkBool32 VKAPI_CALL debugCallback(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                             VkDebugUtilsMessageTypeFlagsEXT types,
                                             const VkDebugUtilsMessengerCallbackDataEXT* data,
                                             void* user) {
    if (user && data && data->pMessage) {
        static_cast<Context*>(user)->recordMessage(severity, types, data->pMessage);
    }
    return VK_FALSE;
}

bool hasLayer(const char* name) {
    uint32_t count = 0;
    vkEnumerateInstanceLayerProperties(&count, nullptr);
    std::vector<VkLayerProperties> layers(count);
    vkEnumerateInstanceLayerProperties(&count, layers.data());
    for (const auto& l : layers) {
        if (std::strcmp(l.layerName, name) == 0) return true;
    }
    return false;
}

bool hasInstanceExtension(const char* name) {
    uint32_t count = 0;
    vkEnumerateInstanceExtensionProperties(nullptr, &count, nullptr);
    std::vector<VkExtensionProperties> exts(count);
    vkEnumerateInstanceExtensionProperties(nullptr, &count, exts.data());
    for (const auto& e : exts) {
        if (std::strcmp(e.extensionName, name) == 0) return true;
    }
    return false;
}

std::string versionString(uint32_t v) {
    return std::to_string(VK_API_VERSION_MAJOR(v)) + "." + std::to_string(VK_API_VERSION_MINOR(v)) +
           "." + std::to_string(VK_API_VERSION_PATCH(v));
}

std::string envString(const char* name) {
    const char* v = std::getenv(name);
    return v ? std::string(v) : std::string();
}

std::string lower(std::string s) {
    for (char& c : s)
        c = char(std::tolower(static_cast<unsigned char>(c)));
    return s;
}

}  // namespace

Context::Context(const ContextOptions& options) {
    std::string envValidation = envString("GILAB_VALIDATION");
    bool sync = options.syncValidation || envValidation == "sync";
    bool validation =
        options.validation || sync || (!envValidation.empty() && envValidation != "0");
    createInstance(validation, sync);
    std::string filter = envString("GILAB_DEVICE");
    if (filter.empty()) filter = options.deviceFilter;
    try {
        pickDevice(filter);
        createDevice();
    } catch (...) {
        if (m_messenger) {
            auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
                vkGetInstanceProcAddr(m_instance, "vkDestroyDebugUtilsMessengerEXT"));
            if (destroy) destroy(m_instance, m_messenger, nullptr);
        }
        vkDestroyInstance(m_instance, nullptr);
        throw;
    }
}

Context::~Context() {
    if (m_memory.allocationCount() > 0) {
        std::string tags;
        for (const auto& [tag, bytes] : m_memory.byTag())
            tags += " " + tag;
        std::fprintf(stderr, "gilab: Context destroyed with %zu live allocations:%s\n",
                     m_memory.allocationCount(), tags.c_str());
    }
    if (m_device) {
        vkDeviceWaitIdle(m_device);
        if (m_fence) vkDestroyFence(m_device, m_fence, nullptr);
        if (m_commandPool) vkDestroyCommandPool(m_device, m_commandPool, nullptr);
        vkDestroyDevice(m_device, nullptr);
    }
    if (m_messenger) {
        auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
            vkGetInstanceProcAddr(m_instance, "vkDestroyDebugUtilsMessengerEXT"));
        if (destroy) destroy(m_instance, m_messenger, nullptr);
    }
    if (m_instance) vkDestroyInstance(m_instance, nullptr);
}

void Context::createInstance(bool validation, bool syncValidation) {
    uint32_t loaderVersion = VK_API_VERSION_1_0;
    vkEnumerateInstanceVersion(&loaderVersion);
    if (loaderVersion < VK_API_VERSION_1_3) {
        throw Error("the Vulkan loader supports only " + versionString(loaderVersion) +
                    "; gilab needs Vulkan 1.3 (install libvulkan1 >= 1.3)");
    }
    if (validation && !hasLayer(kValidationLayer)) {
        throw Error(std::string("Vulkan validation was requested but ") + kValidationLayer +
                    " is not installed (apt-get install vulkan-validationlayers)");
    }
    m_validation = validation;
    m_debugUtils = validation && hasInstanceExtension(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);

    VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
    app.pApplicationName = "gilab";
    app.applicationVersion = VK_MAKE_API_VERSION(0, 0, 1, 0);
    app.pEngineName = "gilab";
    app.engineVersion = VK_MAKE_API_VERSION(0, 0, 1, 0);
    app.apiVersion = VK_API_VERSION_1_3;

    std::vector<const char*> layers;
    std::vector<const char*> extensions;
    if (m_validation) layers.push_back(kValidationLayer);
    if (m_debugUtils) extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);

    VkDebugUtilsMessengerCreateInfoEXT messengerInfo{
        VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
    messengerInfo.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT |
                                    VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
    messengerInfo.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT |
                                VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                                VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
    messengerInfo.pfnUserCallback = debugCallback;
    messengerInfo.pUserData = this;

    // Synchronization validation (hazards between commands) on request.
    VkValidationFeatureEnableEXT syncFeature =
        VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT;
    VkValidationFeaturesEXT validationFeatures{VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT};
    validationFeatures.enabledValidationFeatureCount = 1;
    validationFeatures.pEnabledValidationFeatures = &syncFeature;

    VkInstanceCreateInfo info{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
    info.pApplicationInfo = &app;
    info.enabledLayerCount = uint32_t(layers.size());
    info.ppEnabledLayerNames = layers.data();
    info.enabledExtensionCount = uint32_t(extensions.size());
    info.ppEnabledExtensionNames = extensions.data();
    if (m_debugUtils) {
        info.pNext = &messengerInfo;
        if (syncValidation) messengerInfo.pNext = &validationFeatures;
    }
    VK_CHECK(vkCreateInstance(&info, nullptr, &m_instance));

    if (m_debugUtils) {
        messengerInfo.pNext = nullptr;
        auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
            vkGetInstanceProcAddr(m_instance, "vkCreateDebugUtilsMessengerEXT"));
        if (create) VK_CHECK(create(m_instance, &messengerInfo, nullptr, &m_messenger));
        m_setObjectName = reinterpret_cast<PFN_vkSetDebugUtilsObjectNameEXT>(
            vkGetInstanceProcAddr(m_instance, "vkSetDebugUtilsObjectNameEXT"));
    }
}

void Context::pickDevice(const std::string& filter) {
    uint32_t count = 0;
    VK_CHECK(vkEnumeratePhysicalDevices(m_instance, &count, nullptr));
    std::vector<VkPhysicalDevice> devices(count);
    VK_CHECK(vkEnumeratePhysicalDevices(m_instance, &count, devices.data()));
    if (count == 0) {
        throw Error("no Vulkan device found (is mesa-vulkan-drivers installed for lavapipe?)");
    }

    bool byIndex = !filter.empty() && std::all_of(filter.begin(), filter.end(), [](char c) {
        return std::isdigit(static_cast<unsigned char>(c));
    });
    std::vector<DeviceSupport> support;
    int best = -1;
    for (uint32_t i = 0; i < count; ++i) {
        support.push_back(queryDeviceSupport(devices[i]));
        const DeviceSupport& s = support.back();
        DeviceCandidate c;
        c.name = s.name;
        c.type = s.typeName;
        bool matches =
            filter.empty() || (byIndex ? std::stoul(filter) == i
                                       : lower(s.name).find(lower(filter)) != std::string::npos);
        if (!matches) {
            c.reason = "excluded by device filter '" + filter + "'";
        } else if (!s.missing.empty()) {
            c.reason = "lacks ";
            for (size_t k = 0; k < s.missing.size(); ++k) {
                c.reason += (k ? ", " : "") + s.missing[k];
            }
        } else {
            c.reason = "usable";
            if (best < 0 || s.typeRank < support[size_t(best)].typeRank) best = int(i);
        }
        m_candidates.push_back(c);
    }

    auto list = [&]() {
        std::string text;
        for (size_t i = 0; i < m_candidates.size(); ++i) {
            text += (i ? "; " : "") + std::string("[") + std::to_string(i) + "] " +
                    m_candidates[i].name + " (" + m_candidates[i].type +
                    "): " + m_candidates[i].reason;
        }
        return text;
    };
    if (best < 0) {
        std::string message;
        if (!filter.empty()) {
            message = "no usable Vulkan device matches device filter '" + filter +
                      "' (--device or GILAB_DEVICE); candidates: " + list();
        } else {
            message = "no usable Vulkan device: ";
            for (size_t i = 0; i < m_candidates.size(); ++i) {
                message += (i ? "; " : "") + m_candidates[i].name + ": " + m_candidates[i].reason;
            }
        }
        throw Error(message);  // printed once, by whoever catches it
    }

    for (size_t i = 0; i < m_candidates.size(); ++i) {
        if (int(i) == best) {
            m_candidates[i].chosen = true;
            m_candidates[i].reason = "chosen: " + m_candidates[i].type +
                                     " device with every required feature" +
                                     (filter.empty() ? "" : " matching filter '" + filter + "'");
        } else if (m_candidates[i].reason == "usable") {
            m_candidates[i].reason = "usable, but lower preference than " + m_candidates[best].name;
        }
    }
    const DeviceSupport& s = support[size_t(best)];
    m_physicalDevice = devices[size_t(best)];
    m_properties = s.properties;
    m_queueFamily = s.queueFamily;
    m_driverName = s.driverName;
    m_driverInfo = s.driverInfo;
    m_timestampValidBits = s.timestampValidBits;
    m_timestampsSupported = s.timestampValidBits > 0 && s.properties.limits.timestampPeriod > 0;
    vkGetPhysicalDeviceMemoryProperties(m_physicalDevice, &m_memoryProperties);
}

void Context::createDevice() {
    DeviceSupport s = queryDeviceSupport(m_physicalDevice);
    EnabledFeatures enabled;
    chooseFeatures(s, enabled);
    m_enabledExtensions = enabled.extensions;
    m_floatAtomics = enabled.floatAtomics;
    m_conservativeRaster = enabled.conservativeRaster;
    m_fillModeNonSolid = enabled.features2.features.fillModeNonSolid == VK_TRUE;
    m_storageReadWithoutFormat =
        enabled.features2.features.shaderStorageImageReadWithoutFormat == VK_TRUE;
    m_descriptorIndexing = enabled.descriptorIndexing;
    m_multiview = enabled.v11.multiview == VK_TRUE;

    float priority = 1.0f;
    VkDeviceQueueCreateInfo queueInfo{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
    queueInfo.queueFamilyIndex = m_queueFamily;
    queueInfo.queueCount = 1;
    queueInfo.pQueuePriorities = &priority;

    std::vector<const char*> extensions;
    for (const auto& e : m_enabledExtensions)
        extensions.push_back(e.c_str());
    VkDeviceCreateInfo info{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
    info.pNext = &enabled.features2;
    info.queueCreateInfoCount = 1;
    info.pQueueCreateInfos = &queueInfo;
    info.enabledExtensionCount = uint32_t(extensions.size());
    info.ppEnabledExtensionNames = extensions.data();
    VK_CHECK(vkCreateDevice(m_physicalDevice, &info, nullptr, &m_device));
    vkGetDeviceQueue(m_device, m_queueFamily, 0, &m_queue);

    VkCommandPoolCreateInfo poolInfo{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    poolInfo.flags = VK_COMMAND_POOL_CREATE_TRANSIENT_BIT;
    poolInfo.queueFamilyIndex = m_queueFamily;
    VK_CHECK(vkCreateCommandPool(m_device, &poolInfo, nullptr, &m_commandPool));
    setDebugName(VK_OBJECT_TYPE_COMMAND_POOL, uint64_t(m_commandPool), "context/commandPool");
    VkFenceCreateInfo fenceInfo{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    VK_CHECK(vkCreateFence(m_device, &fenceInfo, nullptr, &m_fence));
    setDebugName(VK_OBJECT_TYPE_FENCE, uint64_t(m_fence), "context/submitFence");
}

std::string Context::deviceName() const {
    return m_properties.deviceName;
}

std::string Context::deviceType() const {
    return deviceTypeName(m_properties.deviceType);
}

std::string Context::driverName() const {
    return m_driverName;
}

std::string Context::driverInfo() const {
    return m_driverInfo;
}

std::string Context::apiVersion() const {
    return versionString(m_properties.apiVersion);
}

bool Context::isExtensionEnabled(const std::string& name) const {
    return std::find(m_enabledExtensions.begin(), m_enabledExtensions.end(), name) !=
           m_enabledExtensions.end();
}

void Context::recordMessage(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                            VkDebugUtilsMessageTypeFlagsEXT types, const char* message) {
    bool error = (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT) != 0;
    bool warning = (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT) != 0;
    if (!error && !warning) return;  // INFO / VERBOSE are ignored
    std::string text = std::string(error ? "[error] " : "[warning] ") + message;
    std::lock_guard lock(m_messageMutex);
    if (error) {
        ++m_errorCount;
    } else {
        ++m_warningCount;
    }
    if (m_messages.size() < 1000) m_messages.push_back(text);
    if (m_errorCount + m_warningCount <= 20) std::fprintf(stderr, "vulkan: %s\n", text.c_str());
}

uint32_t Context::validationErrorCount() const {
    std::lock_guard lock(m_messageMutex);
    return m_errorCount;
}

uint32_t Context::validationWarningCount() const {
    std::lock_guard lock(m_messageMutex);
    return m_warningCount;
}

std::vector<std::string> Context::validationMessages() const {
    std::lock_guard lock(m_messageMutex);
    return m_messages;
}

void Context::clearValidationMessages() {
    std::lock_guard lock(m_messageMutex);
    m_messages.clear();
    m_errorCount = 0;
    m_warningCount = 0;
}

void Context::submitAndWait(const std::function<void(VkCommandBuffer)>& record) {
    std::lock_guard lock(m_submitMutex);
    VkCommandBufferAllocateInfo alloc{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    alloc.commandPool = m_commandPool;
    alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    alloc.commandBufferCount = 1;
    VkCommandBuffer cmd = VK_NULL_HANDLE;
    VK_CHECK(vkAllocateCommandBuffers(m_device, &alloc, &cmd));
    try {
        VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
        begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
        VK_CHECK(vkBeginCommandBuffer(cmd, &begin));
        record(cmd);
        VK_CHECK(vkEndCommandBuffer(cmd));

        VkCommandBufferSubmitInfo cmdInfo{VK_STRUCTURE_TYPE_COMMAND_BUFFER_SUBMIT_INFO};
        cmdInfo.commandBuffer = cmd;
        VkSubmitInfo2 submit{VK_STRUCTURE_TYPE_SUBMIT_INFO_2};
        submit.commandBufferInfoCount = 1;
        submit.pCommandBufferInfos = &cmdInfo;
        VK_CHECK(vkResetFences(m_device, 1, &m_fence));
        VK_CHECK(vkQueueSubmit2(m_queue, 1, &submit, m_fence));
        VK_CHECK(vkWaitForFences(m_device, 1, &m_fence, VK_TRUE, UINT64_MAX));
    } catch (...) {
        vkQueueWaitIdle(m_queue);
        vkFreeCommandBuffers(m_device, m_commandPool, 1, &cmd);
        vkResetCommandPool(m_device, m_commandPool, 0);
        throw;
    }
    vkFreeCommandBuffers(m_device, m_commandPool, 1, &cmd);
    vkResetCommandPool(m_device, m_commandPool, 0);
}

void Context::setDebugName(VkObjectType type, uint64_t handle, const std::string& name) const {
    if (!m_setObjectName || handle == 0 || name.empty()) return;
    VkDebugUtilsObjectNameInfoEXT info{VK_STRUCTURE_TYPE_DEBUG_UTILS_OBJECT_NAME_INFO_EXT};
    info.objectType = type;
    info.objectHandle = handle;
    info.pObjectName = name.c_str();
    m_setObjectName(m_device, &info);
}

uint32_t Context::tryFindMemoryType(uint32_t typeBits, VkMemoryPropertyFlags flags) const {
    for (uint32_t i = 0; i < m_memoryProperties.memoryTypeCount; ++i) {
        if ((typeBits & (1u << i)) &&
            (m_memoryProperties.memoryTypes[i].propertyFlags & flags) == flags) {
            return i;
        }
    }
    return UINT32_MAX;
}

uint32_t Context::findMemoryType(uint32_t typeBits, VkMemoryPropertyFlags flags) const {
    uint32_t type = tryFindMemoryType(typeBits, flags);
    if (type == UINT32_MAX) {
        throw Error("no Vulkan memory type with flags " + std::to_string(flags) + " in type bits " +
                    std::to_string(typeBits) + " on " + deviceName());
    }
    return type;
}

}  // namespace gilab::vk
