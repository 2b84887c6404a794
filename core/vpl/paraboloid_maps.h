#pragma once
/**
 * Hemispherical paraboloid maps (Heidrich & Seidel 1998), one per VPL cluster, all rendered in
 * one layered pass through a geometry shader (Aranha et al. §III-C; clustered visibility, Dong et
 * al. 2009). Layer i is seen from clusters[i].position along clusters[i].normal; inactive
 * clusters leave their layer empty. Each map is itself an RSM (position + radial distance,
 * normal, albedo), so it serves both the visibility test of the cluster's VPLs and the drawing
 * of second-bounce VPLs. Mapping, clipping and exactness: shaders/common/paraboloid.geom/.frag,
 * docs/vpl.md. Layers are in GENERAL after record() (read them as storage images).
 */
#include <cstdint>
#include <string>

#include <vulkan/vulkan.h>

#include "core/vk/descriptors.h"
#include "core/vk/image.h"
#include "core/vk/pipeline.h"

namespace gilab {
namespace vk {
class Buffer;
class Context;
class GpuScene;
}  // namespace vk

struct ParaboloidSettings {
    uint32_t resolution = 256;        // texels per side (paper 256)
    uint32_t layers = 8;              // clusters
    float far = 1.0f;                 // radial distance at depth 1 (>= the scene's diameter)
    float maxEdgeAngleRad = 0.2618f;  // split triangles until edges subtend <= 15 deg ...
    uint32_t maxSubdivision = 4;      // ... with at most this many splits per edge (1..4)
};

class ParaboloidMaps {
public:
    /** clusters: at least settings.layers VplCluster entries (core/vpl/vpl.h). */
    ParaboloidMaps(vk::Context& ctx, const vk::GpuScene& scene, const vk::Buffer& clusters,
                   const ParaboloidSettings& settings, const std::string& tag);
    ParaboloidMaps(const ParaboloidMaps&) = delete;
    ParaboloidMaps& operator=(const ParaboloidMaps&) = delete;

    /** The per-frame triangle split rule (paraboloid.geom). */
    void setSubdivision(uint32_t maxSubdivision, float maxEdgeAngleRad);
    /** Clears and renders every layer (one instanced, layered draw of the scene). */
    void record(VkCommandBuffer cmd) { record(cmd, 0, m_settings.layers); }
    /**
     * Renders layers [first, first + count) only. first = 0 clears every layer first; a later
     * range keeps the layers below it as rendered (ssvp's second-bounce maps, drawn after the
     * first-bounce ones are read).
     */
    void record(VkCommandBuffer cmd, uint32_t first, uint32_t count);

    vk::Image& position() { return m_position; }
    vk::Image& normal() { return m_normal; }
    vk::Image& albedo() { return m_albedo; }
    const ParaboloidSettings& settings() const { return m_settings; }
    uint64_t bytes() const;

private:
    const vk::GpuScene& m_scene;
    ParaboloidSettings m_settings;
    vk::Image m_position, m_normal, m_albedo, m_depth;
    vk::DescriptorSetLayout m_setLayout;
    vk::DescriptorSet m_set;
    vk::PipelineLayout m_layout;
    vk::GraphicsPipeline m_pipeline;
};

}  // namespace gilab
