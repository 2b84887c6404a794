#pragma once
/**
 * Embedded SPIR-V registry. cmake/GilabShaders.cmake generates, per shader, a static
 * ShaderRegistration{"common/foo.comp", words, sizeInBytes}; lookups use that name.
 */
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <vulkan/vulkan.h>

#include "core/vk/handle.h"

namespace gilab::vk {

class Context;

struct ShaderRegistration {
    /** `bytes` is the size of `words` in bytes. */
    ShaderRegistration(const char* name, const uint32_t* words, size_t bytes);
};

/** Throws gilab::Error listing the registered names when `name` is missing. */
std::span<const uint32_t> findShader(const std::string& name);
bool hasShader(const std::string& name);
/** Sorted. */
std::vector<std::string> registeredShaders();

class ShaderModule {
public:
    ShaderModule() = default;
    ShaderModule(Context& ctx, const std::string& name);
    VkShaderModule handle() const { return m_module.handle(); }
    const std::string& name() const { return m_name; }

private:
    ShaderModuleHandle m_module;
    std::string m_name;
};

}  // namespace gilab::vk
