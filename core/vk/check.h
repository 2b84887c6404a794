#pragma once
/** VK_CHECK: turns a failing VkResult into a gilab::Error naming the call, result and place. */
#include <string>

#include <vulkan/vulkan.h>

#include "core/util/error.h"

namespace gilab::vk {

/** "VK_ERROR_OUT_OF_DEVICE_MEMORY" etc.; "VK_RESULT(<n>)" for unknown codes. */
const char* resultName(VkResult result);

/** Throws gilab::Error("<expr> failed: <result> at <file>:<line>"). */
[[noreturn]] void throwVkError(const char* expr, VkResult result, const char* file, int line);

}  // namespace gilab::vk

#define VK_CHECK(expr)                                                            \
    do {                                                                          \
        VkResult gilabVkResult_ = (expr);                                         \
        if (gilabVkResult_ != VK_SUCCESS) {                                       \
            ::gilab::vk::throwVkError(#expr, gilabVkResult_, __FILE__, __LINE__); \
        }                                                                         \
    } while (0)
