#include "core/vk/sampler.h"

#include <algorithm>

#include "core/vk/check.h"
#include "core/vk/context.h"

namespace gilab::vk {

Sampler::Sampler(Context& ctx, const SamplerDesc& desc) {
    auto axis = [&](VkSamplerAddressMode mode) {
        return mode == VK_SAMPLER_ADDRESS_MODE_MAX_ENUM ? desc.address : mode;
    };
    VkSamplerCreateInfo info{VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO};
    info.magFilter = desc.filter;
    info.minFilter = desc.filter;
    info.mipmapMode = desc.mipmap;
    info.addressModeU = axis(desc.addressU);
    info.addressModeV = axis(desc.addressV);
    info.addressModeW = axis(desc.addressW);
    info.minLod = desc.minLod;
    info.maxLod = desc.maxLod;
    info.borderColor = desc.borderColor;
    float maxAniso = ctx.properties().limits.maxSamplerAnisotropy;
    if (desc.maxAnisotropy > 1.0f) {
        info.anisotropyEnable = VK_TRUE;
        info.maxAnisotropy = std::min(desc.maxAnisotropy, maxAniso);
    }
    info.compareEnable = desc.compare ? VK_TRUE : VK_FALSE;
    info.compareOp = desc.compareOp;
    VkSampler sampler = VK_NULL_HANDLE;
    VK_CHECK(vkCreateSampler(ctx.device(), &info, nullptr, &sampler));
    m_sampler = SamplerHandle(ctx.device(), sampler);
    ctx.setDebugName(VK_OBJECT_TYPE_SAMPLER, uint64_t(sampler), desc.name);
}

}  // namespace gilab::vk
