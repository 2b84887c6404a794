#include "core/vk/check.h"

#include <string>
#include <utility>

namespace gilab::vk {

const char* resultName(VkResult result) {
    switch (result) {
#define GILAB_RESULT(r) \
    case r:             \
        return #r;
        GILAB_RESULT(VK_SUCCESS)
        GILAB_RESULT(VK_NOT_READY)
        GILAB_RESULT(VK_TIMEOUT)
        GILAB_RESULT(VK_EVENT_SET)
        GILAB_RESULT(VK_EVENT_RESET)
        GILAB_RESULT(VK_INCOMPLETE)
        GILAB_RESULT(VK_ERROR_OUT_OF_HOST_MEMORY)
        GILAB_RESULT(VK_ERROR_OUT_OF_DEVICE_MEMORY)
        GILAB_RESULT(VK_ERROR_INITIALIZATION_FAILED)
        GILAB_RESULT(VK_ERROR_DEVICE_LOST)
        GILAB_RESULT(VK_ERROR_MEMORY_MAP_FAILED)
        GILAB_RESULT(VK_ERROR_LAYER_NOT_PRESENT)
        GILAB_RESULT(VK_ERROR_EXTENSION_NOT_PRESENT)
        GILAB_RESULT(VK_ERROR_FEATURE_NOT_PRESENT)
        GILAB_RESULT(VK_ERROR_INCOMPATIBLE_DRIVER)
        GILAB_RESULT(VK_ERROR_TOO_MANY_OBJECTS)
        GILAB_RESULT(VK_ERROR_FORMAT_NOT_SUPPORTED)
        GILAB_RESULT(VK_ERROR_FRAGMENTED_POOL)
        GILAB_RESULT(VK_ERROR_UNKNOWN)
        GILAB_RESULT(VK_ERROR_OUT_OF_POOL_MEMORY)
        GILAB_RESULT(VK_ERROR_INVALID_EXTERNAL_HANDLE)
        GILAB_RESULT(VK_ERROR_FRAGMENTATION)
        GILAB_RESULT(VK_ERROR_INVALID_OPAQUE_CAPTURE_ADDRESS)
        GILAB_RESULT(VK_PIPELINE_COMPILE_REQUIRED)
        GILAB_RESULT(VK_ERROR_SURFACE_LOST_KHR)
        GILAB_RESULT(VK_ERROR_NATIVE_WINDOW_IN_USE_KHR)
        GILAB_RESULT(VK_SUBOPTIMAL_KHR)
        GILAB_RESULT(VK_ERROR_OUT_OF_DATE_KHR)
        GILAB_RESULT(VK_ERROR_INCOMPATIBLE_DISPLAY_KHR)
        GILAB_RESULT(VK_ERROR_VALIDATION_FAILED_EXT)
        GILAB_RESULT(VK_ERROR_INVALID_SHADER_NV)
#undef GILAB_RESULT
        default:
            return "VK_RESULT_UNKNOWN";
    }
}

void throwVkError(const char* expr, VkResult result, const char* file, int line) {
    std::string name = resultName(result);
    if (name == "VK_RESULT_UNKNOWN") name = "VkResult(" + std::to_string(int(result)) + ")";
    throw Error(std::string(expr) + " failed: " + name + " at " + file + ":" +
                std::to_string(line));
}

bool isOutOfMemory(VkResult result) {
    return result == VK_ERROR_OUT_OF_DEVICE_MEMORY || result == VK_ERROR_OUT_OF_HOST_MEMORY;
}

OutOfMemoryError::OutOfMemoryError(const std::string& step, const std::string& kind,
                                   std::string resource, uint64_t bytes, VkResult result)
    : DeviceLimitError(step + " " + std::to_string(bytes) + " bytes (" +
                       std::to_string(bytes >> 20) + " MiB) " +
                       (step == "binding" ? "of memory to " : "for ") + kind + " '" + resource +
                       "' failed: " + resultName(result)),
      m_resource(std::move(resource)),
      m_bytes(bytes),
      m_result(result) {}

}  // namespace gilab::vk
