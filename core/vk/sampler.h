#pragma once
/** RAII VkSampler from a small description. */
#include <string>

#include <vulkan/vulkan.h>

#include "core/vk/handle.h"

namespace gilab::vk {

class Context;

struct SamplerDesc {
    VkFilter filter = VK_FILTER_LINEAR;  // mag and min
    VkSamplerMipmapMode mipmap = VK_SAMPLER_MIPMAP_MODE_LINEAR;
    VkSamplerAddressMode address = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
    /** Per-axis overrides; VK_SAMPLER_ADDRESS_MODE_MAX_ENUM = use `address`. */
    VkSamplerAddressMode addressU = VK_SAMPLER_ADDRESS_MODE_MAX_ENUM;
    VkSamplerAddressMode addressV = VK_SAMPLER_ADDRESS_MODE_MAX_ENUM;
    VkSamplerAddressMode addressW = VK_SAMPLER_ADDRESS_MODE_MAX_ENUM;
    VkBorderColor borderColor = VK_BORDER_COLOR_FLOAT_OPAQUE_WHITE;
    float minLod = 0.0f;
    float maxLod = VK_LOD_CLAMP_NONE;
    float maxAnisotropy = 1.0f;  // > 1 only when the device supports samplerAnisotropy
    bool compare = false;        // depth compare (shadow samplers)
    VkCompareOp compareOp = VK_COMPARE_OP_LESS_OR_EQUAL;
    std::string name;
};

class Sampler {
public:
    Sampler() = default;
    Sampler(Context& ctx, const SamplerDesc& desc);
    VkSampler handle() const { return m_sampler.handle(); }

private:
    SamplerHandle m_sampler;
};

}  // namespace gilab::vk
