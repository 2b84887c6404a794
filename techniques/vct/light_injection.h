#pragma once
/**
 * Light injection of `vct` (Crassin et al. 2011 §8.2; notes 001 §2.5), dense storage.
 * The caller wraps these in the timed pass "inject"; each step is also timed inside it as
 * "inject.light_view", "inject.photons", "inject.splat", "inject.shade":
 *   light view     rasterise the scene from every light into a light-view map (a reflective
 *                  shadow map holding the world position and the shading normal per texel):
 *                  spot = one perspective map over the outer cone (a cube above
 *                  kSpotCubeOuterDeg), point = 6 cube faces, directional = one orthographic map
 *                  fitted to the voxel grid, emitter sample (the shared area-light samples,
 *                  docs/shared_passes.md) = a hemicube around its normal (the front face and the
 *                  4 half side faces; 6 full faces when double-sided)
 *   photons        one photon per texel: flux = I(w) x texel solid angle (pinhole; I(w) with the
 *                  spot falloff or the sample's cosine lobe) or E x texel area (directional), and
 *                  the irradiance at the hit E = I(w) cos(theta) / r^2 (E_perp cos(theta)); a hit
 *                  facing away from the light carries nothing
 *   splat          per light, one thread per photon: every covered voxel its footprint reaches
 *                  gets the photon's E; the voxel keeps the light's mean E (sum of E / count),
 *                  summed over lights (splat_dense_body.glsl). The photon's flux is also added
 *                  to its voxel (flux planes: a diagnostic whose sum is the injected flux)
 *   shade          one thread per voxel: outgoing diffuse radiance premultiplied by coverage,
 *                  rgb = a * albedo / pi * E, into a radiance volume's base
 * Map sizes: `light_map_resolution` texels per side, or (0) from the footprint rule: a texel's
 * footprint on the farthest grid corner in front of the view is at most kTexelFootprintVoxels v0
 * (directional: map side / texels <= kTexelFootprintVoxels v0), clamped to the device's image and
 * storage-buffer limits (noted). The dense path processes the photons in batches of whole lights
 * (at most LightViewLimits::batchBytes each, unless one light needs more) to bound the scratch
 * memory; the octree needs them all at once in one storage buffer, so its maps shrink instead.
 * The photon buffer is also what the sparse voxel octree injects (techniques/vct/svo.h).
 * Set-up injects once; when lights move (VctTechnique::update, issue 11) refresh() re-plans the
 * views for the scene's current lights and the steps above are recorded again (as the paper
 * re-injects when a light moves).
 */
#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include <vulkan/vulkan.h>
#include <glm/glm.hpp>

#include "core/passes/emitter_samples.h"
#include "core/vk/buffer.h"
#include "core/vk/descriptors.h"
#include "core/vk/image.h"
#include "core/vk/pipeline.h"
#include "core/vk/sampler.h"
#include "core/voxel/voxel_grid.h"
#include "photons.h"

namespace gilab {
struct Scene;
struct TechniqueContext;
namespace vk {
class Context;
class GpuScene;
}  // namespace vk

namespace vct {

/** Emission lobe of a light view (GpuLightView::intensity.w, LIGHT_VIEW_LOBE_* in GLSL). */
enum LightViewLobe : uint32_t {
    kLobeUniform = 0,         // point light
    kLobeSpot = 1,            // glTF spot falloff around spotAxis
    kLobeCosine = 2,          // emitter sample: max(0, n . w)
    kLobeCosineTwoSided = 3,  // double-sided emitter sample: |n . w|
};

/** One light-view map; mirrors LightView in techniques/vct/shaders/light_view.glsl (std430). */
struct GpuLightView {
    glm::mat4 viewProj{1.0f};      // world -> Vulkan clip (reversed Z)
    glm::vec4 positionKind{0.0f};  // xyz light position (pinhole) or window centre (ortho);
                                   // w 0 = pinhole, 1 = orthographic
    glm::vec4 forward{0.0f};       // pinhole: texel ray = forward + ndc.x axisX + ndc.y axisY, on
                                   // the unit-distance image plane; ortho: travel direction
    glm::vec4 axisX{0.0f};         // xyz half-extent vector (unit plane / world), w its length
    glm::vec4 axisY{0.0f};
    glm::vec4 intensity{0.0f};  // rgb I [W/sr] (point, spot; sample: along its normal) or
                                // E [W/m^2] (directional); w LightViewLobe
    glm::vec4 spotAxis{0.0f};   // xyz spot direction (travel) or emitter normal, w 1 = spot
    glm::vec4 cone{0.0f};       // x cos(inner), y cos(outer), z scene light index (-1 - k for
                                // emitter sample k), w skip distance from skipPlane (0 = none)
    glm::vec4 skipPlane{0.0f};  // xyz unit normal, w offset: dot(xyz, p) + w = 0
    glm::uvec4 texels{0u};      // x width, y height, z first photon in its batch, w map layer
    glm::uvec4 group{0u};       // x light index, y its first view, z its view count, w batch
};
static_assert(sizeof(GpuLightView) == 224);

/** Spots with an outer cone above this use a cube map (as the shared shadow maps do). */
inline constexpr float kSpotCubeOuterDeg = 80.0f;
/** Auto map size: largest texel footprint on the farthest grid corner, in leaf voxels. */
inline constexpr float kTexelFootprintVoxels = 0.5f;

/**
 * Light-view maps for every punctual light of `scene`, then a hemicube per emitter sample
 * (`samples`, e.g. ShadowMaps::emitterSamples()); `grid` places the directional maps. Sizes and
 * batches are not assigned (texels = 0): see planLightViews.
 */
std::vector<GpuLightView> buildLightViews(const Scene& scene, const VoxelGrid& grid,
                                          const std::vector<EmitterSample>& samples = {});

/** Upper bound of a view's radiant flux (all texels, hit or not): I x window solid angle (exact
 *  for point lights), or E x window area (directional). For tests and fixed-point scales. */
glm::dvec3 lightViewFluxBound(const GpuLightView& view);

/** Width and height from the footprint rule (before clamping). */
glm::uvec2 footprintResolution(const GpuLightView& view, const VoxelGrid& grid);

struct LightViewLimits {
    uint64_t photonBufferBytes = 128ull << 20;  // min(maxStorageBufferRange, 128 MiB)
    uint64_t batchBytes = 32ull << 20;          // photons per batch, unless one light needs more
    uint32_t maxImageDimension = 16384;         // maxImageDimension2D
    bool singleBatch = false;                   // every photon in one buffer (octree)
};

struct LightViewBatch {
    uint32_t firstView = 0, viewCount = 0;
    uint32_t firstLight = 0, lightCount = 0;
    uint64_t photons = 0;
    uint32_t maxWidth = 0, maxHeight = 0;
};

struct LightViewPlan {
    std::vector<GpuLightView> views;  // sizes, photon offsets, layers and batches assigned
    std::vector<LightViewBatch> batches;
    std::vector<std::string> notes;  // clamps (also ctx.note()d by LightInjection)
    uint32_t lightCount = 0;
    uint64_t photonCount = 0;  // all batches
    uint32_t maxWidth = 0, maxHeight = 0, maxLayers = 0;
    uint64_t maxBatchPhotons = 0;
};

/** Sizes the maps (mapResolution texels per side, 0 = footprint rule; a light whose photons
 *  exceed limits.photonBufferBytes shrinks, and with singleBatch so do all) and packs whole
 *  lights into batches of at most limits.batchBytes of photons (or the largest light's). */
LightViewPlan planLightViews(std::vector<GpuLightView> views, const VoxelGrid& grid,
                             uint32_t mapResolution, const LightViewLimits& limits);

class LightInjection {
public:
    /** mapResolution: texels per side of each light-view map, 0 = from the footprint rule.
     *  singleBatch: keep every photon in one buffer (the octree injects them at once). */
    LightInjection(TechniqueContext& ctx, const VoxelGrid& grid, uint32_t mapResolution,
                   bool singleBatch = false);
    LightInjection(const LightInjection&) = delete;
    LightInjection& operator=(const LightInjection&) = delete;

    /** Light-view maps and photon generation of the first (or only) batch ("light_view",
     *  "photons"). */
    void recordPhotons(TechniqueContext& ctx, VkCommandBuffer cmd);
    /** Dense: clears the accumulators and splats the first batch's photons ("splat"), then
     *  records the light views, photons and splat of every further batch. `albedoOpacity` is
     *  the voxelizer's volume (SHADER_READ_ONLY_OPTIMAL): photons go to covered voxels. */
    void recordSplat(TechniqueContext& ctx, VkCommandBuffer cmd, vk::Image& albedoOpacity);
    /** Dense: writes outgoing radiance into `target` (N^3 storage image, GENERAL, RGBA16F or
     *  RGBA32F) ("shade"). */
    void recordShade(TechniqueContext& ctx, VkCommandBuffer cmd, vk::Image& albedoOpacity,
                     vk::Image& target);

    /** The photons of the last recorded batch (all of them when batchCount() == 1). */
    PhotonSource photons() const;
    /**
     * Re-plans the light views for ctx.scene's current lights (moved, turned, new intensity;
     * same number and types of lights) and uploads them: map sizes follow the footprint rule
     * again, the fixed-point scales are recomputed. The photon buffer, the view buffer and the
     * light-view maps are reused when the new plan fits them and grown (never shrunk) when it
     * does not; returns whether anything was reallocated (then photons().buffer may have
     * changed). Record recordPhotons (and recordSplat / recordShade) again afterwards.
     */
    bool refresh(TechniqueContext& ctx);

    /** Photons over all batches. */
    uint64_t photonCount() const { return m_plan.photonCount; }
    uint32_t viewCount() const { return uint32_t(m_plan.views.size()); }
    uint32_t lightCount() const { return m_plan.lightCount; }
    uint32_t batchCount() const { return uint32_t(m_plan.batches.size()); }
    /** Largest map side over all views. */
    uint32_t mapResolution() const { return std::max(m_plan.maxWidth, m_plan.maxHeight); }
    /** e.g. "512^2 x 1 view" or "64^2..313^2 x 80 views (3 batches)". */
    std::string mapSummary() const;
    const std::vector<GpuLightView>& views() const { return m_plan.views; }
    const LightViewPlan& plan() const { return m_plan; }
    bool usesFloatAtomics() const { return m_floatAtomics; }
    /** Fixed-point scale (units per W) when !usesFloatAtomics(). */
    double fixedScale() const { return m_fixedScale; }

    /** Tests: the photons of the last recorded batch (blocking read-back). */
    std::vector<GpuPhoton> readPhotons();
    /** Tests: the splatted flux per voxel in W (rgb), x + N (y + N z) order. */
    std::vector<glm::vec3> readVoxelFlux();
    /** Tests: the injected irradiance per voxel in W/m^2 (rgb), x + N (y + N z) order. */
    std::vector<glm::vec3> readVoxelIrradiance();
    /** Frees the accumulators (after shading; the octree path never makes them). */
    void releaseAccumulators() {
        m_flux.clear();
        m_irradiance.clear();
        m_count = {};
    }
    size_t memoryBytes() const;

private:
    LightViewPlan makePlan(TechniqueContext& ctx) const;
    void computeScales();
    void allocatePhotons(TechniqueContext& ctx, uint64_t photons);
    void allocateViews(TechniqueContext& ctx, size_t views);
    void allocateMaps(TechniqueContext& ctx, uint32_t width, uint32_t height, uint32_t layers);
    void writePhotonSet();
    void ensureDenseResources(TechniqueContext& ctx);
    void recordLightViews(TechniqueContext& ctx, VkCommandBuffer cmd, uint32_t batch, bool timed);
    void recordBatchSplat(TechniqueContext& ctx, VkCommandBuffer cmd, uint32_t batch, bool timed);
    std::vector<glm::vec3> readPlanes(std::vector<vk::Buffer>& planes, double unitsPer);

    vk::Context& m_vk;
    const vk::GpuScene& m_scene;
    VoxelGrid m_grid;
    uint32_t m_mapResolution = 0;
    LightViewLimits m_limits;
    LightViewPlan m_plan;
    uint64_t m_photonCapacity = 0;  // photons the photon buffer holds
    size_t m_viewCapacity = 0;      // views the view buffer holds
    uint32_t m_recordedBatch = 0;
    bool m_floatAtomics = false;
    double m_fixedScale = 1.0;            // flux units per W
    double m_fixedIrradianceScale = 1.0;  // irradiance units per W/m^2
    std::vector<float> m_irradianceCap;   // per light (fixed point: clamp of a photon's E)

    vk::Buffer m_viewBuffer;
    vk::Buffer m_photons;
    vk::Image m_positionMap;  // 2D array RGBA32F, one layer per view of a batch
    vk::Image m_normalMap;    // 2D array RGBA16F
    vk::Image m_depth;
    vk::PipelineLayout m_rasterLayout;
    vk::GraphicsPipeline m_raster;
    vk::DescriptorSetLayout m_photonSetLayout;
    vk::DescriptorSet m_photonSet;
    vk::PipelineLayout m_photonLayout;
    vk::ComputePipeline m_photonPipeline;

    // Dense path (created on first use)
    std::vector<vk::Buffer> m_flux;        // 3 planes of N^3 words (float or fixed-point uint)
    std::vector<vk::Buffer> m_irradiance;  // 3 planes of N^3 words (float or fixed-point uint)
    vk::Buffer m_count;                    // N^3 uint: deposits of the light being splatted
    vk::Sampler m_nearest;
    vk::DescriptorSetLayout m_splatSetLayout;
    vk::DescriptorSet m_splatSet, m_shadeSet;
    vk::PipelineLayout m_splatLayout;
    vk::ComputePipeline m_splat, m_shade16, m_shade32;
};

}  // namespace vct
}  // namespace gilab
