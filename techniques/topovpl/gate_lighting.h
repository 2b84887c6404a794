#pragma once
/**
 * The per-frame passes of `topovpl` after the G-buffer and the VPLs (Noël & Biri 2014 §V;
 * notes 004 §2.B), on the GPU:
 *   recordVplClusters   the visibility cluster of every VPL
 * (techniques/topovpl/shaders/vpl_cluster.comp) recordIugc          unique geometry clusters: tiles
 * x depth slices x visibility cluster, local sort, world boxes (iugc.comp) recordLa light
 * assignment: per geometry cluster, same-cluster VPLs and (VPL, gate) pairs whose cone reaches its
 * bounding sphere (E8); counted, scanned, then written (la_assign.comp, la_scan.comp) recordIl
 * indirect lighting: the exact gate test (E7), the gather, the near-VPL clamp (il.comp) into the
 * frame's indirect layer readStats() reads the last frame's counters (valid once its submission has
 * finished).
 */
#include <cstdint>
#include <string>
#include <vector>

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

class PixelClusters;

/** Mirrors TopoGate in techniques/topovpl/shaders/topovpl.glsl (std430). */
struct GpuGate {
    glm::vec4 centreRadius{0.0f};
    glm::vec4 normal{0.0f};
    glm::uvec4 clusters{0u};
};
static_assert(sizeof(GpuGate) == 48);

/** The gates and, per visibility cluster, the list of its gates (CSR). */
struct GateTable {
    std::vector<GpuGate> gates;
    std::vector<uint32_t> clusterStart;  // clusterCount + 1 entries
    std::vector<uint32_t> clusterGates;  // each gate under both its clusters
    uint32_t clusterCount = 0;
};

enum class LaMode : uint32_t { Gates = 0, SameCluster = 1, Unshadowed = 2 };

struct GateLightingStats {
    uint32_t geometryClusters = 0;
    uint64_t entries = 0;   // light-assignment entries wanted (0xFFFFFFFF: beyond 32 bits)
    uint64_t overflow = 0;  // entries that did not fit the buffer
    double keptIrradiance = 0.0, removedIrradiance = 0.0;  // clamp sums (mean of rgb)
    uint32_t validVpls = 0, vplsWithoutCluster = 0;
    // recordSameClusterShare: outgoing radiance (mean of rgb) summed over the image, every VPL
    // unshadowed and only the VPLs of the pixel's own visibility cluster.
    double unshadowedRadiance = 0.0, sameClusterRadiance = 0.0;
};

class GateLighting {
public:
    GateLighting(vk::Context& ctx, GBuffer& gbuffer, PixelClusters& pixels, vk::Buffer& vpls,
                 uint32_t vplCount, const GateTable& gates, uint64_t entryCapacity,
                 const std::string& tag);
    GateLighting(const GateLighting&) = delete;
    GateLighting& operator=(const GateLighting&) = delete;

    /** Replaces the gate disks (same count and clusters; e.g. another radius rule). */
    void updateGates(const std::vector<GpuGate>& gates);

    void recordVplClusters(VkCommandBuffer cmd);
    /** eye, forward: the camera; zNear, zFar: the depth-slice range. */
    void recordIugc(VkCommandBuffer cmd, const glm::vec3& eye, const glm::vec3& forward,
                    float zNear, float zFar, uint32_t tile, uint32_t slices);
    void recordLa(VkCommandBuffer cmd, LaMode mode, bool farClusterOnly);
    void recordIl(VkCommandBuffer cmd, vk::Image& indirect, float clampDistance);
    /** Diagnostic (same_cluster_share.comp): every pixel against every VPL, unshadowed, summed
     *  over the image, all pairs and same-visibility-cluster pairs (readStats). */
    void recordSameClusterShare(VkCommandBuffer cmd, float clampDistance);

    GateLightingStats readStats();
    uint64_t entryCapacity() const { return m_capacity; }
    uint64_t bytes() const;
    /** Per pixel: its geometry cluster (R32UI, 0xFFFFFFFF none), GENERAL. */
    vk::Image& geometryClusters() { return m_geoImage; }

private:
    struct Stage {
        vk::DescriptorSetLayout setLayout;
        vk::DescriptorSet set;
        vk::PipelineLayout layout;
        vk::ComputePipeline pipeline;
        void bind(VkCommandBuffer cmd) const;
    };
    /** One compute pass: a set with `types` at bindings 0, 1, ..., a push block, a shader. */
    static Stage makeStage(vk::Context& ctx, const std::vector<VkDescriptorType>& types,
                           uint32_t pushBytes, const std::string& shader, const std::string& tag);

    uint32_t m_width, m_height, m_vplCount, m_clusterCount;
    uint64_t m_capacity;
    VoxelGrid m_grid;
    vk::Buffer m_vplClusters, m_gates, m_clusterStart, m_clusterGates;
    vk::Buffer m_geo, m_counts, m_offsets, m_entries, m_state, m_partials, m_sharePartials;
    vk::Image m_geoImage;
    vk::Buffer& m_vpls;
    Stage m_vplStage, m_iugc, m_laArgs, m_laAssign, m_laScan, m_il, m_share;
    VkImageView m_boundIndirect = VK_NULL_HANDLE;
};

}  // namespace topo
}  // namespace gilab
