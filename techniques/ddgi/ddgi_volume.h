#pragma once
/**
 * The ddgi probe volume on the GPU (notes 005 §2-§3; techniques/ddgi/README.md): the grid over
 * the scene bounds, the octahedral irradiance and distance atlases (RGBA32F, interior + 1-texel
 * border per probe, G3D tile layout), the probe ray buffer, the probe data (relocation offset,
 * state), the scene's BVH for the GPU ray tracer (core/rt) and the passes:
 *   probe_trace, probe_blend_irradiance, probe_blend_distance, probe_border,
 *   probe_relocation, probe_classification (the update) and gather (the per-pixel query).
 */
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <vulkan/vulkan.h>
#include <glm/glm.hpp>

#include "core/vk/buffer.h"
#include "core/vk/descriptors.h"
#include "core/vk/image.h"
#include "core/vk/pipeline.h"
#include "ddgi_settings.h"

namespace gilab {

struct Bounds;
struct Scene;
struct TechniqueContext;
namespace rt {
class GpuBvh;
}

/** Probe placement: probe (i, j, k) sits at origin + spacing * (i, j, k) (+ its offset). */
struct DdgiGrid {
    glm::vec3 origin{0.0f};
    glm::vec3 spacing{1.0f};
    glm::ivec3 counts{2};
    float maxDistance = 1.0f;  // r_max: stored distances are clamped to it
    uint32_t probeCount() const { return uint32_t(counts.x) * counts.y * counts.z; }
    float minSpacing() const { return glm::min(spacing.x, glm::min(spacing.y, spacing.z)); }
};

/** The grid for the scene bounds (G3D: volume = bounds x volume_scale about the centre,
 *  spacing = extent / (counts - 1)); throws gilab::Error on invalid bounds. */
DdgiGrid makeDdgiGrid(const Bounds& bounds, const DdgiSettings& settings);

/** What one update uses beside the settings. */
struct DdgiFrameInputs {
    float hysteresis = 0.97f;  // for this update (cold-start ramp, events)
    uint32_t updateIndex = 0;  // seeds the random rotation and the light sampling
    glm::vec3 camera{0.0f};
};

/** Arvo's uniformly distributed random rotation from three uniforms in [0, 1). */
glm::mat3 arvoRotation(float u1, float u2, float u3);

/** Point i of the n-point spherical Fibonacci set: phi = 2 pi frac(i (Phi - 1)),
 *  cos theta = 1 - (2 i + 1) / n (G3D, SDK; notes 005 §3.1). */
glm::vec3 sphericalFibonacci(uint32_t i, uint32_t n);

/** The directions of one update's rays: `fixedRays` un-rotated ones (a set of their own), then
 *  the others' set rotated by `rotation`. */
std::vector<glm::vec4> ddgiRayDirections(uint32_t rays, uint32_t fixedRays,
                                         const glm::mat3& rotation);

class DdgiVolume {
public:
    DdgiVolume(TechniqueContext& ctx, const DdgiSettings& settings);
    ~DdgiVolume();
    DdgiVolume(const DdgiVolume&) = delete;
    DdgiVolume& operator=(const DdgiVolume&) = delete;

    /** Zeroes the atlases and the probe data (a cold start). */
    void recordClear(VkCommandBuffer cmd);
    /** Uploads this update's uniforms (the previous frame has finished). */
    void setFrame(const DdgiSettings& settings, const DdgiFrameInputs& inputs);
    /** The probe update passes, each under its name. */
    void recordUpdate(const TechniqueContext& ctx, VkCommandBuffer cmd);
    /** Points the gather at `indirect` (before anything of the frame is recorded: a set must
     *  not be updated while a command buffer that binds it is being recorded). */
    void setIndirectTarget(vk::Image& indirect);
    /** The per-pixel query into the indirect target. */
    void recordGather(const TechniqueContext& ctx, VkCommandBuffer cmd);
    /** Builds the BVH again from the scene's current triangles (moved geometry). */
    void rebuildBvh(const Scene& scene);

    const DdgiGrid& grid() const { return m_grid; }
    const rt::GpuBvh& bvh() const { return *m_bvh; }
    /** Mean luminance of the decoded irradiance over every active probe's interior texels
     *  (read back; blocking). */
    double meanIrradiance();
    /** Probe data read back (xyz offset, w state). */
    std::vector<glm::vec4> readProbeData();
    uint64_t raysPerUpdate() const { return uint64_t(m_grid.probeCount()) * m_rays; }

private:
    void bindAndDispatch(VkCommandBuffer cmd, const vk::ComputePipeline& pipeline,
                         uint32_t pushValue, uint32_t x, uint32_t y, bool twoD);

    vk::Context& m_vk;
    DdgiSettings m_settings;
    DdgiGrid m_grid;
    uint32_t m_rays = 0;
    uint32_t m_width = 0, m_height = 0;
    uint32_t m_punctualLights = 0, m_emitterSamples = 0;
    float m_rayEpsilon = 1e-4f;
    VkDescriptorSet m_sceneSet = VK_NULL_HANDLE;
    std::unique_ptr<rt::GpuBvh> m_bvh;
    vk::Image m_irradiance;
    vk::Image m_distance;
    vk::Buffer m_probeRays;
    vk::Buffer m_probeData;
    vk::Buffer m_uniforms;
    vk::Buffer m_rayDirections;
    vk::DescriptorSetLayout m_setLayout;
    vk::DescriptorSet m_set;
    vk::PipelineLayout m_layout;
    vk::ComputePipeline m_trace, m_blend, m_border, m_relocation, m_classification, m_gather;
    VkImageView m_boundIndirect = VK_NULL_HANDLE;
};

}  // namespace gilab
