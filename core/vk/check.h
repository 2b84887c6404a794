#pragma once
/** VK_CHECK: turns a failing VkResult into a gilab::Error naming the call, result and place. */
#include <cstdint>
#include <string>

#include <vulkan/vulkan.h>

#include "core/util/error.h"

namespace gilab::vk {

/** "VK_ERROR_OUT_OF_DEVICE_MEMORY" etc.; "VK_RESULT(<n>)" for unknown codes. */
const char* resultName(VkResult result);

/** Throws gilab::Error("<expr> failed: <result> at <file>:<line>"). */
[[noreturn]] void throwVkError(const char* expr, VkResult result, const char* file, int line);

/** VK_ERROR_OUT_OF_DEVICE_MEMORY or VK_ERROR_OUT_OF_HOST_MEMORY. */
bool isOutOfMemory(VkResult result);

/**
 * The driver refused memory for a resource: "allocating 4294967296 bytes (4096 MiB) for image
 * 'shared/gbuffer' failed: VK_ERROR_OUT_OF_DEVICE_MEMORY". A DeviceLimitError: the request is
 * valid, this device cannot hold it (a run records it as unsupported; `gilab render` names the
 * resolution).
 */
class OutOfMemoryError : public DeviceLimitError {
public:
    /** `step`: "allocating" or "binding"; `kind`: "image" or "buffer". */
    OutOfMemoryError(const std::string& step, const std::string& kind, std::string resource,
                     uint64_t bytes, VkResult result);
    const std::string& resource() const { return m_resource; }
    uint64_t bytes() const { return m_bytes; }
    VkResult result() const { return m_result; }

private:
    std::string m_resource;
    uint64_t m_bytes = 0;
    VkResult m_result = VK_SUCCESS;
};

}  // namespace gilab::vk

#define VK_CHECK(expr)                                                            \
    do {                                                                          \
        VkResult gilabVkResult_ = (expr);                                         \
        if (gilabVkResult_ != VK_SUCCESS) {                                       \
            ::gilab::vk::throwVkError(#expr, gilabVkResult_, __FILE__, __LINE__); \
        }                                                                         \
    } while (0)
