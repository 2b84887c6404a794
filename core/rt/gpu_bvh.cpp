#include "gpu_bvh.h"

#include "core/vk/context.h"

namespace gilab::rt {

GpuBvh::GpuBvh(vk::Context& ctx, const Scene& scene, const std::string& memoryTag)
    : m_ctx(ctx), m_tag(memoryTag) {
    rebuild(scene);
}

void GpuBvh::addLayoutBindings(std::vector<vk::DescriptorBinding>& bindings, uint32_t first,
                               VkShaderStageFlags stages) {
    bindings.push_back({first, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, stages});
    bindings.push_back({first + 1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, stages});
}

void GpuBvh::writeDescriptors(vk::DescriptorSet& set, uint32_t first) const {
    set.writeBuffer(first, m_nodes);
    set.writeBuffer(first + 1, m_triangles);
}

bool GpuBvh::rebuild(const Scene& scene) {
    const Bvh bvh = buildBvh(scene);
    m_stats = bvh.stats;
    return upload(bvh);
}

bool GpuBvh::upload(const Bvh& bvh) {
    const VkDeviceSize nodeBytes = bvh.nodes.size() * sizeof(BvhNode);
    const VkDeviceSize triangleBytes =
        std::max<VkDeviceSize>(1, bvh.triangles.size()) * sizeof(BvhTriangle);
    bool reallocated = false;
    // Device-local buffers, written by a staging copy once per (re)build
    if (m_nodes.size() < nodeBytes) {
        m_nodes = vk::Buffer(m_ctx, nodeBytes,
                             VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                             vk::MemoryUsage::DeviceLocal, m_tag + "/nodes");
        reallocated = true;
    }
    if (m_triangles.size() < triangleBytes) {
        m_triangles =
            vk::Buffer(m_ctx, triangleBytes,
                       VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                       vk::MemoryUsage::DeviceLocal, m_tag + "/triangles");
        reallocated = true;
    }
    m_nodes.uploadVector(bvh.nodes);
    m_triangles.uploadVector(bvh.triangles);
    return reallocated;
}

}  // namespace gilab::rt
