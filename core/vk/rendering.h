#pragma once
/**
 * Begins dynamic rendering into colour views (+ optional depth view) on construction and ends it
 * on destruction. Sets viewport (positive height; the projection already flips y) and scissor to
 * the extent. Attachments must already be in COLOR_/DEPTH_ATTACHMENT_OPTIMAL (or GENERAL).
 */
#include <optional>
#include <vector>

#include <vulkan/vulkan.h>

namespace gilab::vk {

struct ColorTarget {
    VkImageView view = VK_NULL_HANDLE;
    std::optional<VkClearColorValue> clear;  // nullopt = load
    VkImageLayout layout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
};

struct DepthTarget {
    VkImageView view = VK_NULL_HANDLE;  // null = no depth
    std::optional<float> clear = 1.0f;  // nullopt = load
    VkImageLayout layout = VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL;
    bool store = true;
};

class RenderingScope {
public:
    RenderingScope(VkCommandBuffer cmd, VkExtent2D extent, const std::vector<ColorTarget>& colors,
                   const DepthTarget& depth = {}, uint32_t layerCount = 1, uint32_t viewMask = 0);
    ~RenderingScope();
    RenderingScope(const RenderingScope&) = delete;
    RenderingScope& operator=(const RenderingScope&) = delete;

private:
    VkCommandBuffer m_cmd;
};

}  // namespace gilab::vk
