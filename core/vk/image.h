#pragma once
/** A VkImage with its own memory, a whole-resource view and cached per-layer / per-mip views. */
#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include <vulkan/vulkan.h>

namespace gilab::vk {

class Context;

enum class ImageKind { Image2D, Image2DArray, Cube, CubeArray, Image3D };

struct ImageDesc {
    ImageKind kind = ImageKind::Image2D;
    VkFormat format = VK_FORMAT_R32G32B32A32_SFLOAT;
    uint32_t width = 1, height = 1, depth = 1;
    uint32_t mipLevels = 1;  // 0 = full chain
    uint32_t layers = 1;     // Cube: 6; CubeArray: 6 * n
    VkImageUsageFlags usage = 0;
    std::string name;
};

/** Bytes per texel of the formats we use; throws for unknown/compressed formats. */
uint32_t formatBytesPerTexel(VkFormat format);
bool isDepthFormat(VkFormat format);
bool hasStencil(VkFormat format);
/** Full mip chain length for a size. */
uint32_t fullMipCount(uint32_t width, uint32_t height, uint32_t depth = 1);
/** The description of a plain 2D image (one mip, one layer). */
inline ImageDesc imageDesc2D(uint32_t width, uint32_t height, VkFormat format,
                             VkImageUsageFlags usage, std::string name) {
    ImageDesc d;
    d.format = format;
    d.width = width;
    d.height = height;
    d.usage = usage;
    d.name = std::move(name);
    return d;
}

class Image {
public:
    Image() = default;
    /** TRANSFER_SRC/DST are added to the usage so upload/readback/mips always work, and SAMPLED
     *  where the format supports it. */
    Image(Context& ctx, const ImageDesc& desc);
    ~Image();
    Image(const Image&) = delete;
    Image& operator=(const Image&) = delete;
    Image(Image&& other) noexcept;
    Image& operator=(Image&& other) noexcept;

    VkImage handle() const { return m_image; }
    /** Whole resource, view type matching kind, all mips and layers. */
    VkImageView view() const { return m_view; }
    /** Single-layer 2D view (a cube face, an array layer, or a 3D image's whole slab). Cached. */
    VkImageView layerView(uint32_t layer, uint32_t mip = 0);
    /** View of one mip over all layers, type matching kind (cube kinds become 2D arrays). Cached.
     */
    VkImageView mipView(uint32_t mip);
    const ImageDesc& desc() const { return m_desc; }
    uint32_t width() const { return m_desc.width; }
    uint32_t height() const { return m_desc.height; }
    VkFormat format() const { return m_desc.format; }
    VkExtent2D extent2D() const { return {m_desc.width, m_desc.height}; }
    /** DEPTH for depth formats (+STENCIL where present), else COLOR. */
    VkImageAspectFlags aspect() const;
    VkImageLayout layout() const { return m_layout; }
    bool valid() const { return m_image != VK_NULL_HANDLE; }

    /**
     * Layout transition with a full barrier (all commands -> all commands, all memory access);
     * the layout is tracked in the object. Same newLayout = plain memory barrier.
     */
    void transition(VkCommandBuffer cmd, VkImageLayout newLayout);
    /** Tells the wrapper the layout changed by other means (e.g. a render pass). */
    void setLayout(VkImageLayout layout) { m_layout = layout; }
    /** Transitions to GENERAL and clears every mip and layer. */
    void clearColor(VkCommandBuffer cmd, const VkClearColorValue& value);
    /** Transitions to GENERAL and clears every mip and layer. */
    void clearDepth(VkCommandBuffer cmd, float depth);

    /** Tightly packed texels of mip 0 of `layer`; leaves SHADER_READ_ONLY_OPTIMAL. */
    void upload(Context& ctx, const void* data, size_t bytes, uint32_t layer = 0);
    /** Blit chain from mip 0 for every layer; leaves SHADER_READ_ONLY_OPTIMAL. */
    void generateMips(Context& ctx);
    /** Raw texels, tightly packed; restores the previous layout. */
    std::vector<uint8_t> readback(Context& ctx, uint32_t layer = 0, uint32_t mip = 0);
    /**
     * Texels converted to float (R32/RG32/RGBA32 SFLOAT, R16/RG16/RGBA16 SFLOAT,
     * R8G8B8A8/B8G8R8A8 UNORM/SRGB with sRGB decoded to linear, D32_SFLOAT); others throw.
     */
    std::vector<float> readbackFloat(Context& ctx, uint32_t layer = 0, uint32_t mip = 0,
                                     uint32_t* channelsOut = nullptr);

    VkDescriptorImageInfo descriptor(VkSampler sampler, VkImageLayout layout) const {
        return {sampler, m_view, layout};
    }

private:
    void destroy();
    VkImageView createView(VkImageViewType type, uint32_t baseMip, uint32_t mipCount,
                           uint32_t baseLayer, uint32_t layerCount, const std::string& suffix);

    Context* m_ctx = nullptr;
    ImageDesc m_desc;
    VkImage m_image = VK_NULL_HANDLE;
    VkDeviceMemory m_memory = VK_NULL_HANDLE;
    VkDeviceSize m_allocSize = 0;
    VkImageView m_view = VK_NULL_HANDLE;
    std::map<std::pair<uint32_t, uint32_t>, VkImageView> m_layerViews;
    std::map<uint32_t, VkImageView> m_mipViews;
    VkImageLayout m_layout = VK_IMAGE_LAYOUT_UNDEFINED;
};

}  // namespace gilab::vk
