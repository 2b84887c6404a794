#include "core/vk/shader.h"

#include <map>
#include <mutex>

#include "core/util/error.h"
#include "core/vk/check.h"
#include "core/vk/context.h"

namespace gilab::vk {
namespace {

struct Registry {
    std::mutex mutex;
    std::map<std::string, std::span<const uint32_t>> shaders;
};

// Function-local static: safe to use from other translation units' static initialisers.
Registry& registry() {
    static Registry instance;
    return instance;
}

}  // namespace

ShaderRegistration::ShaderRegistration(const char* name, const uint32_t* words, size_t bytes) {
    Registry& r = registry();
    std::lock_guard lock(r.mutex);
    r.shaders.emplace(name, std::span<const uint32_t>(words, bytes / sizeof(uint32_t)));
}

std::span<const uint32_t> findShader(const std::string& name) {
    Registry& r = registry();
    std::lock_guard lock(r.mutex);
    auto it = r.shaders.find(name);
    if (it != r.shaders.end()) return it->second;
    std::string known;
    for (const auto& [key, words] : r.shaders)
        known += (known.empty() ? "" : ", ") + key;
    throw Error("shader '" + name +
                "' is not registered (is the file in shaders/ and listed in "
                "its CMake target?); registered: " +
                (known.empty() ? "none" : known));
}

bool hasShader(const std::string& name) {
    Registry& r = registry();
    std::lock_guard lock(r.mutex);
    return r.shaders.count(name) != 0;
}

std::vector<std::string> registeredShaders() {
    Registry& r = registry();
    std::lock_guard lock(r.mutex);
    std::vector<std::string> names;
    for (const auto& [key, words] : r.shaders)
        names.push_back(key);
    return names;
}

ShaderModule::ShaderModule(Context& ctx, const std::string& name) : m_name(name) {
    std::span<const uint32_t> code = findShader(name);
    VkShaderModuleCreateInfo info{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
    info.codeSize = code.size_bytes();
    info.pCode = code.data();
    VkShaderModule module = VK_NULL_HANDLE;
    VK_CHECK(vkCreateShaderModule(ctx.device(), &info, nullptr, &module));
    m_module = ShaderModuleHandle(ctx.device(), module);
    ctx.setDebugName(VK_OBJECT_TYPE_SHADER_MODULE, uint64_t(module), "shader/" + name);
}

}  // namespace gilab::vk
