#include "core/vk/image.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include <glm/gtc/packing.hpp>

#include "core/util/error.h"
#include "core/vk/barrier.h"
#include "core/vk/buffer.h"
#include "core/vk/check.h"
#include "core/vk/context.h"

namespace gilab::vk {

uint32_t formatBytesPerTexel(VkFormat format) {
    switch (format) {
        case VK_FORMAT_R8_UNORM:
        case VK_FORMAT_R8_SNORM:
        case VK_FORMAT_R8_UINT:
        case VK_FORMAT_R8_SINT:
        case VK_FORMAT_R8_SRGB:
        case VK_FORMAT_S8_UINT:
            return 1;
        case VK_FORMAT_R8G8_UNORM:
        case VK_FORMAT_R8G8_SNORM:
        case VK_FORMAT_R8G8_UINT:
        case VK_FORMAT_R16_SFLOAT:
        case VK_FORMAT_R16_UNORM:
        case VK_FORMAT_R16_SNORM:
        case VK_FORMAT_R16_UINT:
        case VK_FORMAT_R16_SINT:
        case VK_FORMAT_D16_UNORM:
            return 2;
        case VK_FORMAT_R8G8B8A8_UNORM:
        case VK_FORMAT_R8G8B8A8_SRGB:
        case VK_FORMAT_R8G8B8A8_SNORM:
        case VK_FORMAT_R8G8B8A8_UINT:
        case VK_FORMAT_R8G8B8A8_SINT:
        case VK_FORMAT_B8G8R8A8_UNORM:
        case VK_FORMAT_B8G8R8A8_SRGB:
        case VK_FORMAT_R16G16_SFLOAT:
        case VK_FORMAT_R16G16_UNORM:
        case VK_FORMAT_R16G16_SNORM:
        case VK_FORMAT_R16G16_UINT:
        case VK_FORMAT_R32_SFLOAT:
        case VK_FORMAT_R32_UINT:
        case VK_FORMAT_R32_SINT:
        case VK_FORMAT_D32_SFLOAT:
        case VK_FORMAT_X8_D24_UNORM_PACK32:
        case VK_FORMAT_D24_UNORM_S8_UINT:
        case VK_FORMAT_A2B10G10R10_UNORM_PACK32:
        case VK_FORMAT_A2R10G10B10_UNORM_PACK32:
        case VK_FORMAT_B10G11R11_UFLOAT_PACK32:
        case VK_FORMAT_E5B9G9R9_UFLOAT_PACK32:
            return 4;
        case VK_FORMAT_D32_SFLOAT_S8_UINT:
            return 8;
        case VK_FORMAT_R16G16B16A16_SFLOAT:
        case VK_FORMAT_R16G16B16A16_UNORM:
        case VK_FORMAT_R16G16B16A16_SNORM:
        case VK_FORMAT_R16G16B16A16_UINT:
        case VK_FORMAT_R32G32_SFLOAT:
        case VK_FORMAT_R32G32_UINT:
        case VK_FORMAT_R32G32_SINT:
            return 8;
        case VK_FORMAT_R32G32B32_SFLOAT:
        case VK_FORMAT_R32G32B32_UINT:
            return 12;
        case VK_FORMAT_R32G32B32A32_SFLOAT:
        case VK_FORMAT_R32G32B32A32_UINT:
        case VK_FORMAT_R32G32B32A32_SINT:
            return 16;
        default:
            throw Error("formatBytesPerTexel: unsupported VkFormat " + std::to_string(int(format)));
    }
}

bool isDepthFormat(VkFormat format) {
    switch (format) {
        case VK_FORMAT_D16_UNORM:
        case VK_FORMAT_D32_SFLOAT:
        case VK_FORMAT_X8_D24_UNORM_PACK32:
        case VK_FORMAT_D24_UNORM_S8_UINT:
        case VK_FORMAT_D32_SFLOAT_S8_UINT:
        case VK_FORMAT_D16_UNORM_S8_UINT:
            return true;
        default:
            return false;
    }
}

bool hasStencil(VkFormat format) {
    return format == VK_FORMAT_D24_UNORM_S8_UINT || format == VK_FORMAT_D32_SFLOAT_S8_UINT ||
           format == VK_FORMAT_D16_UNORM_S8_UINT || format == VK_FORMAT_S8_UINT;
}

uint32_t fullMipCount(uint32_t width, uint32_t height, uint32_t depth) {
    uint32_t size = std::max({width, height, depth, 1u});
    uint32_t levels = 1;
    while (size > 1) {
        size >>= 1;
        ++levels;
    }
    return levels;
}

Image::Image(Context& ctx, const ImageDesc& desc) : m_ctx(&ctx), m_desc(desc) {
    ImageDesc& d = m_desc;
    d.width = std::max(d.width, 1u);
    d.height = std::max(d.height, 1u);
    d.depth = d.kind == ImageKind::Image3D ? std::max(d.depth, 1u) : 1u;
    if (d.kind == ImageKind::Image2D || d.kind == ImageKind::Image3D) d.layers = 1;
    if (d.kind == ImageKind::Cube) d.layers = 6;
    if (d.kind == ImageKind::CubeArray && (d.layers == 0 || d.layers % 6 != 0)) {
        throw Error("image '" + d.name + "': a cube array needs a multiple of 6 layers");
    }
    d.layers = std::max(d.layers, 1u);
    uint32_t fullMips = fullMipCount(d.width, d.height, d.depth);
    d.mipLevels = d.mipLevels == 0 ? fullMips : std::min(d.mipLevels, fullMips);
    // SAMPLED is always added where the format allows it, so any image can be read by a shader
    // (and transitioned to SHADER_READ_ONLY_OPTIMAL) without the creator predicting it.
    VkFormatProperties formatFeatures;
    vkGetPhysicalDeviceFormatProperties(ctx.physicalDevice(), d.format, &formatFeatures);
    if (formatFeatures.optimalTilingFeatures & VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT) {
        d.usage |= VK_IMAGE_USAGE_SAMPLED_BIT;
    }
    VkImageUsageFlags usage =
        d.usage | VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;

    VkImageCreateInfo info{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
    info.imageType = d.kind == ImageKind::Image3D ? VK_IMAGE_TYPE_3D : VK_IMAGE_TYPE_2D;
    info.format = d.format;
    info.extent = {d.width, d.height, d.depth};
    info.mipLevels = d.mipLevels;
    info.arrayLayers = d.layers;
    info.samples = VK_SAMPLE_COUNT_1_BIT;
    info.tiling = VK_IMAGE_TILING_OPTIMAL;
    info.usage = usage;
    info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    info.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    if (d.kind == ImageKind::Cube || d.kind == ImageKind::CubeArray) {
        info.flags |= VK_IMAGE_CREATE_CUBE_COMPATIBLE_BIT;
    }
    VkImageFormatProperties formatProps;
    VkResult supported =
        vkGetPhysicalDeviceImageFormatProperties(ctx.physicalDevice(), info.format, info.imageType,
                                                 info.tiling, info.usage, info.flags, &formatProps);
    if (supported != VK_SUCCESS) {
        throw Error("image '" + d.name + "': format " + std::to_string(int(d.format)) +
                    " with usage 0x" + std::to_string(usage) + " is not supported on " +
                    ctx.deviceName());
    }
    VK_CHECK(vkCreateImage(ctx.device(), &info, nullptr, &m_image));

    VkMemoryRequirements req;
    vkGetImageMemoryRequirements(ctx.device(), m_image, &req);
    VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    alloc.allocationSize = req.size;
    alloc.memoryTypeIndex =
        ctx.findMemoryType(req.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
    VkResult result = vkAllocateMemory(ctx.device(), &alloc, nullptr, &m_memory);
    const bool allocated = result == VK_SUCCESS;
    if (allocated) result = vkBindImageMemory(ctx.device(), m_image, m_memory, 0);
    if (result != VK_SUCCESS) {  // allocation or binding refused: release both, name the image
        const std::string step = allocated ? "binding" : "allocating";
        if (allocated) vkFreeMemory(ctx.device(), m_memory, nullptr);
        vkDestroyImage(ctx.device(), m_image, nullptr);
        m_memory = VK_NULL_HANDLE;
        m_image = VK_NULL_HANDLE;
        if (isOutOfMemory(result)) throw OutOfMemoryError(step, "image", d.name, req.size, result);
        throw Error(step + " " + std::to_string(req.size) + " bytes for image '" + d.name +
                    "' failed: " + resultName(result));
    }
    m_allocSize = req.size;
    ctx.memory().add(d.name, m_allocSize);
    ctx.setDebugName(VK_OBJECT_TYPE_IMAGE, uint64_t(m_image), d.name);
    ctx.setDebugName(VK_OBJECT_TYPE_DEVICE_MEMORY, uint64_t(m_memory), d.name);

    VkImageViewType type = VK_IMAGE_VIEW_TYPE_2D;
    switch (d.kind) {
        case ImageKind::Image2D:
            type = VK_IMAGE_VIEW_TYPE_2D;
            break;
        case ImageKind::Image2DArray:
            type = VK_IMAGE_VIEW_TYPE_2D_ARRAY;
            break;
        case ImageKind::Cube:
            type = VK_IMAGE_VIEW_TYPE_CUBE;
            break;
        case ImageKind::CubeArray:
            type = VK_IMAGE_VIEW_TYPE_CUBE_ARRAY;
            break;
        case ImageKind::Image3D:
            type = VK_IMAGE_VIEW_TYPE_3D;
            break;
    }
    m_view = createView(type, 0, d.mipLevels, 0, d.layers, "");
}

Image::~Image() {
    destroy();
}

Image::Image(Image&& other) noexcept {
    *this = std::move(other);
}

Image& Image::operator=(Image&& other) noexcept {
    if (this != &other) {
        destroy();
        m_ctx = std::exchange(other.m_ctx, nullptr);
        m_desc = std::move(other.m_desc);
        m_image = std::exchange(other.m_image, VK_NULL_HANDLE);
        m_memory = std::exchange(other.m_memory, VK_NULL_HANDLE);
        m_allocSize = std::exchange(other.m_allocSize, 0);
        m_view = std::exchange(other.m_view, VK_NULL_HANDLE);
        m_layerViews = std::move(other.m_layerViews);
        m_mipViews = std::move(other.m_mipViews);
        other.m_layerViews.clear();
        other.m_mipViews.clear();
        m_layout = std::exchange(other.m_layout, VK_IMAGE_LAYOUT_UNDEFINED);
    }
    return *this;
}

void Image::destroy() {
    if (!m_ctx) return;
    VkDevice device = m_ctx->device();
    for (auto& [key, view] : m_layerViews)
        vkDestroyImageView(device, view, nullptr);
    for (auto& [key, view] : m_mipViews)
        vkDestroyImageView(device, view, nullptr);
    m_layerViews.clear();
    m_mipViews.clear();
    if (m_view) vkDestroyImageView(device, m_view, nullptr);
    if (m_image) vkDestroyImage(device, m_image, nullptr);
    if (m_memory) {
        vkFreeMemory(device, m_memory, nullptr);
        m_ctx->memory().remove(m_desc.name, m_allocSize);
    }
    m_ctx = nullptr;
    m_view = VK_NULL_HANDLE;
    m_image = VK_NULL_HANDLE;
    m_memory = VK_NULL_HANDLE;
}

VkImageAspectFlags Image::aspect() const {
    if (!isDepthFormat(m_desc.format)) return VK_IMAGE_ASPECT_COLOR_BIT;
    VkImageAspectFlags a = VK_IMAGE_ASPECT_DEPTH_BIT;
    if (hasStencil(m_desc.format)) a |= VK_IMAGE_ASPECT_STENCIL_BIT;
    return a;
}

VkImageView Image::createView(VkImageViewType type, uint32_t baseMip, uint32_t mipCount,
                              uint32_t baseLayer, uint32_t layerCount, const std::string& suffix) {
    VkImageViewCreateInfo info{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
    info.image = m_image;
    info.viewType = type;
    info.format = m_desc.format;
    // Views of depth/stencil formats see depth only (for sampling and attachments).
    VkImageAspectFlags viewAspect =
        isDepthFormat(m_desc.format) ? VK_IMAGE_ASPECT_DEPTH_BIT : VK_IMAGE_ASPECT_COLOR_BIT;
    info.subresourceRange = {viewAspect, baseMip, mipCount, baseLayer, layerCount};
    VkImageView view = VK_NULL_HANDLE;
    VK_CHECK(vkCreateImageView(m_ctx->device(), &info, nullptr, &view));
    m_ctx->setDebugName(VK_OBJECT_TYPE_IMAGE_VIEW, uint64_t(view), m_desc.name + suffix);
    return view;
}

VkImageView Image::layerView(uint32_t layer, uint32_t mip) {
    if (layer >= m_desc.layers || mip >= m_desc.mipLevels) {
        throw Error("image '" + m_desc.name + "': layerView(" + std::to_string(layer) + ", " +
                    std::to_string(mip) + ") out of range");
    }
    auto key = std::make_pair(layer, mip);
    auto it = m_layerViews.find(key);
    if (it != m_layerViews.end()) return it->second;
    VkImageViewType type =
        m_desc.kind == ImageKind::Image3D ? VK_IMAGE_VIEW_TYPE_3D : VK_IMAGE_VIEW_TYPE_2D;
    VkImageView view = createView(type, mip, 1, layer, 1,
                                  ".layer" + std::to_string(layer) + ".mip" + std::to_string(mip));
    m_layerViews.emplace(key, view);
    return view;
}

VkImageView Image::mipView(uint32_t mip) {
    if (mip >= m_desc.mipLevels) {
        throw Error("image '" + m_desc.name + "': mipView(" + std::to_string(mip) +
                    ") out of range");
    }
    auto it = m_mipViews.find(mip);
    if (it != m_mipViews.end()) return it->second;
    VkImageViewType type = VK_IMAGE_VIEW_TYPE_2D_ARRAY;
    if (m_desc.kind == ImageKind::Image2D) type = VK_IMAGE_VIEW_TYPE_2D;
    if (m_desc.kind == ImageKind::Image3D) type = VK_IMAGE_VIEW_TYPE_3D;
    VkImageView view = createView(type, mip, 1, 0, m_desc.layers, ".mip" + std::to_string(mip));
    m_mipViews.emplace(mip, view);
    return view;
}

namespace {
void imageBarrier(VkCommandBuffer cmd, VkImage image, VkImageAspectFlags aspect,
                  VkImageLayout oldLayout, VkImageLayout newLayout, uint32_t baseMip = 0,
                  uint32_t mipCount = VK_REMAINING_MIP_LEVELS) {
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
    barrier.subresourceRange = {aspect, baseMip, mipCount, 0, VK_REMAINING_ARRAY_LAYERS};
    VkDependencyInfo dep{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
    dep.imageMemoryBarrierCount = 1;
    dep.pImageMemoryBarriers = &barrier;
    vkCmdPipelineBarrier2(cmd, &dep);
}
}  // namespace

void Image::transition(VkCommandBuffer cmd, VkImageLayout newLayout) {
    imageBarrier(cmd, m_image, aspect(), m_layout, newLayout);
    m_layout = newLayout;
}

void Image::clearColor(VkCommandBuffer cmd, const VkClearColorValue& value) {
    transition(cmd, VK_IMAGE_LAYOUT_GENERAL);
    VkImageSubresourceRange range{VK_IMAGE_ASPECT_COLOR_BIT, 0, VK_REMAINING_MIP_LEVELS, 0,
                                  VK_REMAINING_ARRAY_LAYERS};
    vkCmdClearColorImage(cmd, m_image, VK_IMAGE_LAYOUT_GENERAL, &value, 1, &range);
    memoryBarrier(cmd);
}

void Image::clearDepth(VkCommandBuffer cmd, float depth) {
    transition(cmd, VK_IMAGE_LAYOUT_GENERAL);
    VkClearDepthStencilValue value{depth, 0};
    VkImageSubresourceRange range{aspect(), 0, VK_REMAINING_MIP_LEVELS, 0,
                                  VK_REMAINING_ARRAY_LAYERS};
    vkCmdClearDepthStencilImage(cmd, m_image, VK_IMAGE_LAYOUT_GENERAL, &value, 1, &range);
    memoryBarrier(cmd);
}

}  // namespace gilab::vk
