#include "core/vk/rendering.h"

namespace gilab::vk {

RenderingScope::RenderingScope(VkCommandBuffer cmd, VkExtent2D extent,
                               const std::vector<ColorTarget>& colors, const DepthTarget& depth,
                               uint32_t layerCount, uint32_t viewMask)
    : m_cmd(cmd) {
    std::vector<VkRenderingAttachmentInfo> colorInfos;
    for (const auto& c : colors) {
        VkRenderingAttachmentInfo a{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
        a.imageView = c.view;
        a.imageLayout = c.layout;
        a.loadOp = c.clear ? VK_ATTACHMENT_LOAD_OP_CLEAR : VK_ATTACHMENT_LOAD_OP_LOAD;
        a.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
        if (c.clear) a.clearValue.color = *c.clear;
        colorInfos.push_back(a);
    }
    VkRenderingAttachmentInfo depthInfo{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
    depthInfo.imageView = depth.view;
    depthInfo.imageLayout = depth.layout;
    depthInfo.loadOp = depth.clear ? VK_ATTACHMENT_LOAD_OP_CLEAR : VK_ATTACHMENT_LOAD_OP_LOAD;
    depthInfo.storeOp =
        depth.store ? VK_ATTACHMENT_STORE_OP_STORE : VK_ATTACHMENT_STORE_OP_DONT_CARE;
    if (depth.clear) depthInfo.clearValue.depthStencil = {*depth.clear, 0};

    VkRenderingInfo info{VK_STRUCTURE_TYPE_RENDERING_INFO};
    info.renderArea = {{0, 0}, extent};
    info.layerCount = viewMask != 0 ? 0 : layerCount;
    info.viewMask = viewMask;
    info.colorAttachmentCount = uint32_t(colorInfos.size());
    info.pColorAttachments = colorInfos.data();
    info.pDepthAttachment = depth.view ? &depthInfo : nullptr;
    vkCmdBeginRendering(cmd, &info);

    VkViewport viewport{0.0f, 0.0f, float(extent.width), float(extent.height), 0.0f, 1.0f};
    VkRect2D scissor{{0, 0}, extent};
    vkCmdSetViewport(cmd, 0, 1, &viewport);
    vkCmdSetScissor(cmd, 0, 1, &scissor);
}

RenderingScope::~RenderingScope() {
    vkCmdEndRendering(m_cmd);
}

}  // namespace gilab::vk
