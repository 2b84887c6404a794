#pragma once
/**
 * Device-memory accounting. Every Buffer/Image records its VkMemoryRequirements size under its
 * name ("<owner>/<resource>", e.g. "shared/gbuffer.normal") and removes it on destruction.
 */
#include <map>
#include <mutex>
#include <string>

#include <vulkan/vulkan.h>

namespace gilab::vk {

class MemoryTracker {
public:
    void add(const std::string& tag, VkDeviceSize bytes);
    void remove(const std::string& tag, VkDeviceSize bytes);
    VkDeviceSize total() const;
    /** Highest total() since construction or the last resetPeak(). */
    VkDeviceSize peak() const;
    /** Live bytes per tag (tags with zero bytes are dropped). */
    std::map<std::string, VkDeviceSize> byTag() const;
    /** Sum of live bytes of tags starting with `prefix` (e.g. "scene/"). */
    VkDeviceSize totalWithPrefix(const std::string& prefix) const;
    /** Sets peak() to the current total(). */
    void resetPeak();
    /** Number of live allocations. */
    size_t allocationCount() const;

private:
    mutable std::mutex m_mutex;
    std::map<std::string, VkDeviceSize> m_byTag;
    VkDeviceSize m_total = 0;
    VkDeviceSize m_peak = 0;
    size_t m_count = 0;
};

}  // namespace gilab::vk
