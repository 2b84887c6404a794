#pragma once
/**
 * The Vulkan instance, the chosen device, its one graphics+compute queue and a command pool for
 * blocking one-off submissions. Headless (no surface extensions), Vulkan 1.3.
 *
 * Device selection: discrete > integrated > virtual > CPU (lavapipe), among devices with API 1.3,
 * a graphics+compute queue and every required feature (see docs/vulkan_backend.md). The choice
 * and the reason each device was taken or rejected are in candidates().
 * Env overrides: GILAB_DEVICE (same syntax as deviceFilter), GILAB_VALIDATION=1 (or =sync).
 */
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <vulkan/vulkan.h>

#include "core/vk/memory.h"

namespace gilab::vk {

struct ContextOptions {
    bool validation = false;
    /** Also synchronization validation (hazards between commands; slower). Implies validation.
     *  Env GILAB_VALIDATION=sync turns it on too. */
    bool syncValidation = false;
    /** "" = auto; else a substring of the device name or a decimal index into the device list. */
    std::string deviceFilter;
};

struct DeviceCandidate {
    std::string name;
    std::string type;  // "discrete", "integrated", "virtual", "cpu", "other"
    bool chosen = false;
    std::string reason;  // why chosen or rejected
};

class Context {
public:
    explicit Context(const ContextOptions& options = {});
    ~Context();
    Context(const Context&) = delete;
    Context& operator=(const Context&) = delete;
    Context(Context&&) = delete;
    Context& operator=(Context&&) = delete;

    VkInstance instance() const { return m_instance; }
    VkPhysicalDevice physicalDevice() const { return m_physicalDevice; }
    VkDevice device() const { return m_device; }
    VkQueue queue() const { return m_queue; }
    uint32_t queueFamily() const { return m_queueFamily; }
    const VkPhysicalDeviceProperties& properties() const { return m_properties; }

    std::string deviceName() const;
    std::string deviceType() const;
    std::string driverName() const;
    std::string driverInfo() const;
    /** "1.3.255" style. */
    std::string apiVersion() const;
    const std::vector<DeviceCandidate>& candidates() const { return m_candidates; }
    const std::vector<std::string>& enabledExtensions() const { return m_enabledExtensions; }
    bool isExtensionEnabled(const std::string& name) const;

    bool validationEnabled() const { return m_validation; }
    /** Messages of severity ERROR. */
    uint32_t validationErrorCount() const;
    /** Messages of severity WARNING. */
    uint32_t validationWarningCount() const;
    /** Every captured message (WARNING and ERROR), prefixed "[error] " / "[warning] ". */
    std::vector<std::string> validationMessages() const;
    void clearValidationMessages();

    bool timestampsSupported() const { return m_timestampsSupported; }
    double timestampPeriodNs() const { return m_properties.limits.timestampPeriod; }
    uint32_t timestampValidBits() const { return m_timestampValidBits; }
    /** VK_EXT_shader_atomic_float enabled with buffer and image float32 add. */
    bool hasFloatAtomics() const { return m_floatAtomics; }
    bool hasConservativeRaster() const { return m_conservativeRaster; }
    bool hasFillModeNonSolid() const { return m_fillModeNonSolid; }
    bool hasStorageReadWithoutFormat() const { return m_storageReadWithoutFormat; }
    /** Vulkan 1.2 descriptor indexing (runtime arrays, non-uniform sampled images, partially
     *  bound, variable count). Optional: lavapipe (Mesa 22.3) lacks it; the scene set does not
     *  need it. */
    bool hasDescriptorIndexing() const { return m_descriptorIndexing; }
    bool hasMultiview() const { return m_multiview; }

    MemoryTracker& memory() { return m_memory; }
    const MemoryTracker& memory() const { return m_memory; }

    /** Records with `record`, submits on the queue and waits on a fence. Thread-safe (serialised).
     */
    void submitAndWait(const std::function<void(VkCommandBuffer)>& record);
    /** No-op without VK_EXT_debug_utils. */
    void setDebugName(VkObjectType type, uint64_t handle, const std::string& name) const;
    /** Throws when no memory type matches. */
    uint32_t findMemoryType(uint32_t typeBits, VkMemoryPropertyFlags flags) const;
    /** Like findMemoryType but returns UINT32_MAX instead of throwing. */
    uint32_t tryFindMemoryType(uint32_t typeBits, VkMemoryPropertyFlags flags) const;

    /** Internal: called by the debug messenger. */
    void recordMessage(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                       VkDebugUtilsMessageTypeFlagsEXT types, const char* message);

private:
    void createInstance(bool validation, bool syncValidation);
    void pickDevice(const std::string& filter);
    void createDevice();

    VkInstance m_instance = VK_NULL_HANDLE;
    VkDebugUtilsMessengerEXT m_messenger = VK_NULL_HANDLE;
    VkPhysicalDevice m_physicalDevice = VK_NULL_HANDLE;
    VkDevice m_device = VK_NULL_HANDLE;
    VkQueue m_queue = VK_NULL_HANDLE;
    uint32_t m_queueFamily = 0;
    VkPhysicalDeviceProperties m_properties{};
    VkPhysicalDeviceMemoryProperties m_memoryProperties{};
    std::string m_driverName;
    std::string m_driverInfo;
    std::vector<DeviceCandidate> m_candidates;
    std::vector<std::string> m_enabledExtensions;

    bool m_validation = false;
    bool m_debugUtils = false;
    bool m_timestampsSupported = false;
    uint32_t m_timestampValidBits = 0;
    bool m_floatAtomics = false;
    bool m_conservativeRaster = false;
    bool m_fillModeNonSolid = false;
    bool m_storageReadWithoutFormat = false;
    bool m_descriptorIndexing = false;
    bool m_multiview = false;

    PFN_vkSetDebugUtilsObjectNameEXT m_setObjectName = nullptr;

    mutable std::mutex m_messageMutex;
    std::vector<std::string> m_messages;
    uint32_t m_errorCount = 0;
    uint32_t m_warningCount = 0;

    std::mutex m_submitMutex;
    VkCommandPool m_commandPool = VK_NULL_HANDLE;
    VkFence m_fence = VK_NULL_HANDLE;

    MemoryTracker m_memory;
};

}  // namespace gilab::vk
