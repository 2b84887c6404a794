#pragma once
/**
 * The per-pixel visibility cluster of the topological VPLs (Noël & Biri 2014 §V-A, the cluster
 * index of its G-buffer): techniques/topovpl/shaders/pixel_cluster.comp looks every G-buffer pixel
 * up in the topology's voxel-cluster grid (a surface pixel through the empty voxel on its normal's
 * side). Outputs: an R32UI image of cluster ids (0xFFFFFFFF: none) and an RGBA32F debug view
 * coloured by cluster (the glTF export's colours), both in GENERAL after record().
 */
#include <cstdint>
#include <string>

#include <vulkan/vulkan.h>
#include <glm/glm.hpp>

#include "core/vk/buffer.h"
#include "core/vk/descriptors.h"
#include "core/vk/image.h"
#include "core/vk/pipeline.h"
#include "core/voxel/voxel_grid.h"

namespace gilab {
namespace vk {
class Context;
}  // namespace vk
struct GBuffer;

namespace topo {

struct SceneTopology;

class PixelClusters {
public:
    PixelClusters(vk::Context& ctx, GBuffer& gbuffer, const SceneTopology& topology,
                  const std::string& tag);
    PixelClusters(const PixelClusters&) = delete;
    PixelClusters& operator=(const PixelClusters&) = delete;

    /** eye: the viewer (camera position), which breaks ties at corners. */
    void record(VkCommandBuffer cmd, const glm::vec3& eye);
    vk::Image& clusters() { return m_clusters; }
    vk::Image& debugView() { return m_debug; }
    /** The topology's voxel-cluster grid on the GPU (uint per voxel, 0xFFFFFFFF solid). */
    const vk::Buffer& voxelClusters() const { return m_voxelClusters; }
    const VoxelGrid& grid() const { return m_grid; }

private:
    uint32_t m_width, m_height;
    VoxelGrid m_grid;
    vk::Buffer m_voxelClusters;
    vk::Image m_clusters, m_debug;
    vk::DescriptorSetLayout m_setLayout;
    vk::DescriptorSet m_set;
    vk::PipelineLayout m_layout;
    vk::ComputePipeline m_pipeline;
};

}  // namespace topo
}  // namespace gilab
