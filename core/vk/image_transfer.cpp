// Image uploads, mip generation and readback (the blocking, submitAndWait side of Image).
#include <cmath>
#include <cstring>

#include <glm/gtc/packing.hpp>

#include "core/util/error.h"
#include "core/vk/barrier.h"
#include "core/vk/buffer.h"
#include "core/vk/context.h"
#include "core/vk/image.h"

namespace gilab::vk {
namespace {

void levelBarrier(VkCommandBuffer cmd, VkImage image, VkImageAspectFlags aspect, uint32_t mip,
                  VkImageLayout oldLayout, VkImageLayout newLayout) {
    VkImageMemoryBarrier2 barrier{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2};
    barrier.srcStageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT;
    barrier.srcAccessMask = VK_ACCESS_2_MEMORY_WRITE_BIT;
    barrier.dstStageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT;
    barrier.dstAccessMask = VK_ACCESS_2_MEMORY_READ_BIT | VK_ACCESS_2_MEMORY_WRITE_BIT;
    barrier.oldLayout = oldLayout;
    barrier.newLayout = newLayout;
    barrier.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    barrier.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    barrier.image = image;
    barrier.subresourceRange = {aspect, mip, 1, 0, VK_REMAINING_ARRAY_LAYERS};
    VkDependencyInfo dep{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
    dep.imageMemoryBarrierCount = 1;
    dep.pImageMemoryBarriers = &barrier;
    vkCmdPipelineBarrier2(cmd, &dep);
}

float srgbToLinear(float c) {
    return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

}  // namespace

void Image::upload(Context& ctx, const void* data, size_t bytes, uint32_t layer) {
    const ImageDesc& d = m_desc;
    size_t expected = size_t(d.width) * d.height * d.depth * formatBytesPerTexel(d.format);
    if (bytes != expected || layer >= d.layers) {
        throw Error("image '" + d.name + "': upload of " + std::to_string(bytes) +
                    " bytes to layer " + std::to_string(layer) + ", expected " +
                    std::to_string(expected) + " bytes and a layer < " + std::to_string(d.layers));
    }
    Buffer staging(ctx, bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, MemoryUsage::Upload,
                   "staging/" + d.name);
    staging.upload(data, bytes);
    ctx.submitAndWait([&](VkCommandBuffer cmd) {
        transition(cmd, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL);
        VkBufferImageCopy copy{};
        copy.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, layer, 1};
        if (isDepthFormat(d.format)) copy.imageSubresource.aspectMask = VK_IMAGE_ASPECT_DEPTH_BIT;
        copy.imageExtent = {d.width, d.height, d.depth};
        vkCmdCopyBufferToImage(cmd, staging.handle(), m_image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                               1, &copy);
        transition(cmd, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
    });
}

void Image::generateMips(Context& ctx) {
    const ImageDesc& d = m_desc;
    VkFormatProperties props;
    vkGetPhysicalDeviceFormatProperties(ctx.physicalDevice(), d.format, &props);
    VkFilter filter =
        (props.optimalTilingFeatures & VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT)
            ? VK_FILTER_LINEAR
            : VK_FILTER_NEAREST;
    ctx.submitAndWait([&](VkCommandBuffer cmd) {
        if (d.mipLevels <= 1) {
            transition(cmd, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
            return;
        }
        transition(cmd, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL);
        for (uint32_t mip = 1; mip < d.mipLevels; ++mip) {
            levelBarrier(cmd, m_image, aspect(), mip - 1, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                         VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
            VkImageBlit blit{};
            blit.srcSubresource = {aspect(), mip - 1, 0, d.layers};
            blit.srcOffsets[1] = {int32_t(std::max(d.width >> (mip - 1), 1u)),
                                  int32_t(std::max(d.height >> (mip - 1), 1u)),
                                  int32_t(std::max(d.depth >> (mip - 1), 1u))};
            blit.dstSubresource = {aspect(), mip, 0, d.layers};
            blit.dstOffsets[1] = {int32_t(std::max(d.width >> mip, 1u)),
                                  int32_t(std::max(d.height >> mip, 1u)),
                                  int32_t(std::max(d.depth >> mip, 1u))};
            vkCmdBlitImage(cmd, m_image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, m_image,
                           VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &blit, filter);
        }
        for (uint32_t mip = 0; mip < d.mipLevels; ++mip) {
            levelBarrier(cmd, m_image, aspect(), mip,
                         mip + 1 < d.mipLevels ? VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL
                                               : VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                         VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
        }
        m_layout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
    });
}

std::vector<uint8_t> Image::readback(Context& ctx, uint32_t layer, uint32_t mip) {
    const ImageDesc& d = m_desc;
    if (layer >= d.layers || mip >= d.mipLevels) {
        throw Error("image '" + d.name + "': readback of layer " + std::to_string(layer) + " mip " +
                    std::to_string(mip) + " out of range");
    }
    uint32_t w = std::max(d.width >> mip, 1u);
    uint32_t h = std::max(d.height >> mip, 1u);
    uint32_t z = std::max(d.depth >> mip, 1u);
    uint32_t texel = formatBytesPerTexel(d.format);
    if (hasStencil(d.format)) {
        throw Error("image '" + d.name + "': readback of depth/stencil formats is unsupported");
    }
    size_t bytes = size_t(w) * h * z * texel;
    Buffer staging(ctx, bytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT, MemoryUsage::Readback,
                   "staging/" + d.name + ".readback");
    VkImageLayout previous = m_layout;
    ctx.submitAndWait([&](VkCommandBuffer cmd) {
        transition(cmd, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
        VkBufferImageCopy copy{};
        copy.imageSubresource = {isDepthFormat(d.format)
                                     ? VkImageAspectFlags(VK_IMAGE_ASPECT_DEPTH_BIT)
                                     : VkImageAspectFlags(VK_IMAGE_ASPECT_COLOR_BIT),
                                 mip, layer, 1};
        copy.imageExtent = {w, h, z};
        vkCmdCopyImageToBuffer(cmd, m_image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, staging.handle(),
                               1, &copy);
        hostReadBarrier(cmd);
        // Restore the previous layout (UNDEFINED cannot be a target; keep TRANSFER_SRC then).
        if (previous != VK_IMAGE_LAYOUT_UNDEFINED && previous != VK_IMAGE_LAYOUT_PREINITIALIZED) {
            transition(cmd, previous);
        }
    });
    std::vector<uint8_t> out(bytes);
    staging.download(out.data(), bytes);
    return out;
}

std::vector<float> Image::readbackFloat(Context& ctx, uint32_t layer, uint32_t mip,
                                        uint32_t* channelsOut) {
    VkFormat f = m_desc.format;
    uint32_t channels = 0;
    switch (f) {
        case VK_FORMAT_R32_SFLOAT:
        case VK_FORMAT_R16_SFLOAT:
        case VK_FORMAT_D32_SFLOAT:
        case VK_FORMAT_R8_UNORM:
        case VK_FORMAT_R16_UNORM:
        case VK_FORMAT_D16_UNORM:
            channels = 1;
            break;
        case VK_FORMAT_R32G32_SFLOAT:
        case VK_FORMAT_R16G16_SFLOAT:
        case VK_FORMAT_R8G8_UNORM:
            channels = 2;
            break;
        case VK_FORMAT_B10G11R11_UFLOAT_PACK32:
        case VK_FORMAT_R32G32B32_SFLOAT:
            channels = 3;
            break;
        case VK_FORMAT_R32G32B32A32_SFLOAT:
        case VK_FORMAT_R16G16B16A16_SFLOAT:
        case VK_FORMAT_R8G8B8A8_UNORM:
        case VK_FORMAT_R8G8B8A8_SRGB:
        case VK_FORMAT_B8G8R8A8_UNORM:
        case VK_FORMAT_B8G8R8A8_SRGB:
        case VK_FORMAT_A2B10G10R10_UNORM_PACK32:
            channels = 4;
            break;
        default:
            throw Error("image '" + m_desc.name + "': readbackFloat does not support VkFormat " +
                        std::to_string(int(f)));
    }
    std::vector<uint8_t> raw = readback(ctx, layer, mip);
    size_t texels = raw.size() / formatBytesPerTexel(f);
    std::vector<float> out(texels * channels);
    const uint8_t* p = raw.data();
    auto u16 = [&](size_t i) {
        uint16_t v;
        std::memcpy(&v, p + 2 * i, 2);
        return v;
    };
    auto u32 = [&](size_t i) {
        uint32_t v;
        std::memcpy(&v, p + 4 * i, 4);
        return v;
    };
    switch (f) {
        case VK_FORMAT_R32_SFLOAT:
        case VK_FORMAT_D32_SFLOAT:
        case VK_FORMAT_R32G32_SFLOAT:
        case VK_FORMAT_R32G32B32_SFLOAT:
        case VK_FORMAT_R32G32B32A32_SFLOAT:
            std::memcpy(out.data(), p, out.size() * sizeof(float));
            break;
        case VK_FORMAT_R16_SFLOAT:
        case VK_FORMAT_R16G16_SFLOAT:
        case VK_FORMAT_R16G16B16A16_SFLOAT:
            for (size_t i = 0; i < out.size(); ++i)
                out[i] = glm::unpackHalf1x16(u16(i));
            break;
        case VK_FORMAT_R16_UNORM:
        case VK_FORMAT_D16_UNORM:
            for (size_t i = 0; i < out.size(); ++i)
                out[i] = float(u16(i)) / 65535.0f;
            break;
        case VK_FORMAT_R8_UNORM:
        case VK_FORMAT_R8G8_UNORM:
        case VK_FORMAT_R8G8B8A8_UNORM:
            for (size_t i = 0; i < out.size(); ++i)
                out[i] = float(p[i]) / 255.0f;
            break;
        case VK_FORMAT_R8G8B8A8_SRGB:
            for (size_t i = 0; i < out.size(); ++i) {
                float v = float(p[i]) / 255.0f;
                out[i] = (i % 4 == 3) ? v : srgbToLinear(v);
            }
            break;
        case VK_FORMAT_B8G8R8A8_UNORM:
        case VK_FORMAT_B8G8R8A8_SRGB:
            for (size_t t = 0; t < texels; ++t) {
                const uint8_t* q = p + 4 * t;
                float rgba[4] = {q[2] / 255.0f, q[1] / 255.0f, q[0] / 255.0f, q[3] / 255.0f};
                for (int c = 0; c < 4; ++c) {
                    bool decode = f == VK_FORMAT_B8G8R8A8_SRGB && c < 3;
                    out[4 * t + c] = decode ? srgbToLinear(rgba[c]) : rgba[c];
                }
            }
            break;
        case VK_FORMAT_B10G11R11_UFLOAT_PACK32:
            for (size_t t = 0; t < texels; ++t) {
                glm::vec3 v = glm::unpackF2x11_1x10(u32(t));
                out[3 * t] = v.x;
                out[3 * t + 1] = v.y;
                out[3 * t + 2] = v.z;
            }
            break;
        case VK_FORMAT_A2B10G10R10_UNORM_PACK32:
            for (size_t t = 0; t < texels; ++t) {
                uint32_t v = u32(t);
                out[4 * t] = float(v & 1023u) / 1023.0f;
                out[4 * t + 1] = float((v >> 10) & 1023u) / 1023.0f;
                out[4 * t + 2] = float((v >> 20) & 1023u) / 1023.0f;
                out[4 * t + 3] = float(v >> 30) / 3.0f;
            }
            break;
        default:
            break;
    }
    if (channelsOut) *channelsOut = channels;
    return out;
}

}  // namespace gilab::vk
