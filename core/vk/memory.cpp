#include "core/vk/memory.h"

#include <algorithm>

namespace gilab::vk {

void MemoryTracker::add(const std::string& tag, VkDeviceSize bytes) {
    std::lock_guard lock(m_mutex);
    m_byTag[tag] += bytes;
    m_total += bytes;
    m_peak = std::max(m_peak, m_total);
    ++m_count;
}

void MemoryTracker::remove(const std::string& tag, VkDeviceSize bytes) {
    std::lock_guard lock(m_mutex);
    auto it = m_byTag.find(tag);
    if (it == m_byTag.end()) return;  // unknown tag: ignore rather than corrupt the totals
    VkDeviceSize removed = std::min(bytes, it->second);
    it->second -= removed;
    if (it->second == 0) m_byTag.erase(it);
    m_total -= removed;
    if (m_count > 0) --m_count;
}

VkDeviceSize MemoryTracker::total() const {
    std::lock_guard lock(m_mutex);
    return m_total;
}

VkDeviceSize MemoryTracker::peak() const {
    std::lock_guard lock(m_mutex);
    return m_peak;
}

std::map<std::string, VkDeviceSize> MemoryTracker::byTag() const {
    std::lock_guard lock(m_mutex);
    return m_byTag;
}

VkDeviceSize MemoryTracker::totalWithPrefix(const std::string& prefix) const {
    std::lock_guard lock(m_mutex);
    VkDeviceSize sum = 0;
    for (auto it = m_byTag.lower_bound(prefix); it != m_byTag.end(); ++it) {
        if (it->first.compare(0, prefix.size(), prefix) != 0) break;
        sum += it->second;
    }
    return sum;
}

void MemoryTracker::resetPeak() {
    std::lock_guard lock(m_mutex);
    m_peak = m_total;
}

size_t MemoryTracker::allocationCount() const {
    std::lock_guard lock(m_mutex);
    return m_count;
}

}  // namespace gilab::vk
