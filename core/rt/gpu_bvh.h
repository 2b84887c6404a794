#pragma once
/**
 * The scene's BVH on the GPU (core/rt/bvh.h): two storage buffers that any compute pass binds
 * to trace rays with shaders/common/rt_trace.glsl (rtClosest, rtOccluded).
 *
 *   GpuBvh bvh(vk, scene, "<owner>/bvh");
 *   GpuBvh::addLayoutBindings(bindings, 10, VK_SHADER_STAGE_COMPUTE_BIT);   // 10 and 11
 *   bvh.writeDescriptors(set, 10);
 *   // GLSL: define RT_SET 1 and RT_BINDING 10, then include common/rt_trace.glsl
 *
 * rebuild() builds again from the scene's current triangles (moved geometry) and re-uploads;
 * the buffers grow when needed, in which case the descriptors must be written again
 * (rebuild() returns true then). A scene without motion builds once.
 */
#include <cstdint>
#include <string>
#include <vector>

#include <vulkan/vulkan.h>

#include "bvh.h"
#include "core/vk/buffer.h"
#include "core/vk/descriptors.h"

namespace gilab {
struct Scene;
namespace vk {
class Context;
}
}  // namespace gilab

namespace gilab::rt {

class GpuBvh {
public:
    GpuBvh(vk::Context& ctx, const Scene& scene, const std::string& memoryTag);
    GpuBvh(const GpuBvh&) = delete;
    GpuBvh& operator=(const GpuBvh&) = delete;

    /** Bindings `first` (nodes) and `first + 1` (triangles), storage buffers. */
    static void addLayoutBindings(std::vector<vk::DescriptorBinding>& bindings, uint32_t first,
                                  VkShaderStageFlags stages);
    void writeDescriptors(vk::DescriptorSet& set, uint32_t first) const;
    /** Builds from the scene's current triangles and uploads (the GPU must not be reading the
     *  buffers). Returns true when the buffers were re-allocated (write the descriptors again). */
    bool rebuild(const Scene& scene);

    const BvhStats& stats() const { return m_stats; }
    uint64_t bytes() const { return m_nodes.size() + m_triangles.size(); }

private:
    bool upload(const Bvh& bvh);

    vk::Context& m_ctx;
    std::string m_tag;
    BvhStats m_stats;
    vk::Buffer m_nodes;
    vk::Buffer m_triangles;
};

}  // namespace gilab::rt
