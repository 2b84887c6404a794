#pragma once
/**
 * Shading with VPLs (docs/vpl.md): interleaved gathering of a VPL buffer at every G-buffer pixel
 * (shaders/common/vpl_gather.comp), optional clustered visibility through paraboloid maps, a
 * near-VPL clamp whose removed irradiance is measured, then an edge-aware blur of the irradiance
 * and the albedo (shaders/common/vpl_blur.comp), written as outgoing diffuse radiance
 * albedo / pi x E into the frame's indirect layer.
 *
 * recordGather() and recordResolve() are the two halves (Aranha et al. §III-D: shading, then
 * denoising). readClampStats() reads the clamp sums of the last completed gather.
 */
#include <cstdint>
#include <string>

#include <vulkan/vulkan.h>
#include <glm/glm.hpp>

#include "core/vk/buffer.h"
#include "core/vk/descriptors.h"
#include "core/vk/image.h"
#include "core/vk/pipeline.h"

namespace gilab {
namespace vk {
class Context;
}  // namespace vk
struct GBuffer;
class ParaboloidMaps;

/** Which VPLs of a Hammersley-ordered set each interleaved sub-image gets
 *  (shaders/common/vpl.glsl vplInterleaveSubset; docs/vpl.md "Gathering"). */
enum class InterleaveSubsets : uint32_t {
    Fold = 0,    // xor of the index's chunks: one VPL of every elementary box to each subset
    Blocks = 1,  // runs of L consecutive VPLs round-robin
    Modulo = 2,  // k mod I^2 (one strip of the RSM per subset)
};
/** Parses "fold" | "blocks" | "modulo" (throws gilab::Error otherwise). */
InterleaveSubsets interleaveSubsetsFrom(const std::string& name);

struct VplShadingSettings {
    uint32_t interleave = 4;  // I: an I x I pattern of VPL subsets (1 = every VPL)
    InterleaveSubsets subsets = InterleaveSubsets::Blocks;
    float clampDistance = 0.0f;         // d_min in world units; 0 = no clamp
    float visibilityBiasTexels = 1.5f;  // paraboloid test tolerance, map texels at the receiver
    uint32_t blurRadius = 4;            // pixels; 0 = no blur
    glm::vec2 bounceScale{1.0f, 1.0f};  // flux multiplier of bounce 1 and bounce 2 VPLs
    bool visibility = true;             // test VPLs with a layer against the maps
};

/** What the clamp removed in one frame (sums over pixels of the mean of rgb). */
struct VplClampStats {
    double keptIrradiance = 0.0;     // sum of the clamped E [W/m^2]
    double removedIrradiance = 0.0;  // sum of (unclamped - clamped) E
    uint32_t pixels = 0;
    double removedPercent() const {
        const double total = keptIrradiance + removedIrradiance;
        return total > 0.0 ? 100.0 * removedIrradiance / total : 0.0;
    }
};

class VplShading {
public:
    /** maps may be null (no visibility: every VPL unshadowed). */
    VplShading(vk::Context& ctx, GBuffer& gbuffer, const vk::Buffer& vpls,
               const vk::Buffer& clusters, ParaboloidMaps* maps, const std::string& tag);
    VplShading(const VplShading&) = delete;
    VplShading& operator=(const VplShading&) = delete;

    void setSettings(const VplShadingSettings& settings) { m_settings = settings; }
    const VplShadingSettings& settings() const { return m_settings; }
    /** Irradiance from vpls[0 .. count) into irradiance(). The list is Hammersley-ordered sets
     *  (each spread over the sub-images on its own): vpls[0 .. firstCount) is one, the rest are
     *  sets of groupSize (0: the rest is one set). */
    void recordGather(VkCommandBuffer cmd, uint32_t count, uint32_t firstCount,
                      uint32_t groupSize = 0);
    /** Blur + albedo into `indirect` (RGBA32F storage image, GENERAL). */
    void recordResolve(VkCommandBuffer cmd, vk::Image& indirect);
    /** The clamp sums of the last gather (valid once its submission has finished). */
    VplClampStats readClampStats();
    /** The gathered irradiance before the blur (GENERAL). */
    vk::Image& irradiance() { return m_irradiance; }

private:
    void bind(VkCommandBuffer cmd, const vk::ComputePipeline& pipeline,
              const vk::PipelineLayout& layout, const vk::DescriptorSet& set);

    VplShadingSettings m_settings;
    uint32_t m_width = 0, m_height = 0, m_mapResolution = 1;
    bool m_hasMaps = false;
    vk::Image m_irradiance, m_temp, m_dummyMap;
    vk::Buffer m_partials;
    vk::DescriptorSetLayout m_gatherSetLayout, m_blurSetLayout;
    vk::DescriptorSet m_gatherSet, m_blurSet;
    vk::PipelineLayout m_gatherLayout, m_blurLayout;
    vk::ComputePipeline m_gather, m_blur;
    VkImageView m_boundIndirect = VK_NULL_HANDLE;
};

}  // namespace gilab
