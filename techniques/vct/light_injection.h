#pragma once
/**
 * Light injection of `vct` (Crassin et al. 2011 §8.2; notes 001 §2.5), dense storage:
 * The caller wraps these in the timed pass "inject"; each step is also timed inside it as
 * "inject.light_view", "inject.photons", "inject.splat", "inject.shade":
 *   light view     rasterise the scene from every punctual light into a light-view map (a
 *                  reflective shadow map holding the world position per texel): spot = one
 *                  perspective map over the outer cone (a cube above kSpotCubeOuterDeg), point =
 *                  6 cube faces, directional = one orthographic map covering the voxel grid
 *   photons        one photon per texel: flux = I x texel solid angle x spot falloff
 *                  (pinhole dOmega = dx dy / (1 + x^2 + y^2)^{3/2} at unit distance), or
 *                  E x texel area for a directional light; written to a GpuPhoton buffer
 *   splat          one thread per photon: atomic add of the flux into the voxel holding it
 *                  (float atomics, or 32-bit fixed point with a global scale)
 *   shade          one thread per voxel: outgoing diffuse radiance premultiplied by coverage,
 *                  rgb = a * albedo / pi * sum(flux) / v0^2, into a radiance volume's base
 * The photon buffer is also what the sparse voxel octree injects (techniques/vct/svo.h).
 * Lights are static, so this runs once in set-up (the paper re-injects when the light moves).
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
#include "core/vk/sampler.h"
#include "core/voxel/voxel_grid.h"
#include "techniques/vct/photons.h"

namespace gilab {
struct Scene;
struct TechniqueContext;
namespace vk {
class Context;
class GpuScene;
}  // namespace vk

namespace vct {

/** One light-view map layer; mirrors LightView in shaders/vct/light_view.glsl (std430). */
struct GpuLightView {
    glm::mat4 viewProj{1.0f};      // world -> Vulkan clip (reversed Z)
    glm::vec4 positionKind{0.0f};  // xyz light position (perspective) or map centre (ortho);
                                   // w 0 = perspective (pinhole), 1 = orthographic
    glm::vec4 forward{0.0f};       // xyz texel ray = forward + ndc.x axisX + ndc.y axisY
    glm::vec4 axisX{0.0f};         // xyz, w tan(half fov) (perspective) or half width (ortho)
    glm::vec4 axisY{0.0f};
    glm::vec4 intensity{0.0f};  // rgb I [W/sr] (point, spot) or E [W/m^2] (directional)
    glm::vec4 spotAxis{0.0f};   // xyz spot direction (travel), w 1 = spot falloff applies
    glm::vec4 cone{0.0f};       // x cos(inner), y cos(outer) (spot), z scene light index
};
static_assert(sizeof(GpuLightView) == 176);

/** Spots with an outer cone above this use a cube map (as the shared shadow maps do). */
inline constexpr float kSpotCubeOuterDeg = 80.0f;

/** Light-view map layers for every punctual light of `scene`; `grid` places directional maps. */
std::vector<GpuLightView> buildLightViews(const Scene& scene, const VoxelGrid& grid);

/** Analytic radiant flux of a light's views (all texels, hit or not), for tests and scales. */
glm::dvec3 lightViewFluxBound(const GpuLightView& view);

class LightInjection {
public:
    /** mapResolution: texels per side of each light-view map. */
    LightInjection(TechniqueContext& ctx, const VoxelGrid& grid, uint32_t mapResolution);
    LightInjection(const LightInjection&) = delete;
    LightInjection& operator=(const LightInjection&) = delete;

    /** Light-view maps and photon generation ("light_view", "photons"). */
    void recordPhotons(TechniqueContext& ctx, VkCommandBuffer cmd);
    /** Dense: clears the flux accumulators and splats the photons ("splat"). `albedoOpacity`
     *  is the voxelizer's volume (SHADER_READ_ONLY_OPTIMAL), used to snap photons into covered
     *  voxels. */
    void recordSplat(TechniqueContext& ctx, VkCommandBuffer cmd, vk::Image& albedoOpacity);
    /** Dense: writes outgoing radiance into `target` (N^3 storage image, GENERAL, RGBA16F or
     *  RGBA32F) ("shade"). */
    void recordShade(TechniqueContext& ctx, VkCommandBuffer cmd, vk::Image& albedoOpacity,
                     vk::Image& target);

    PhotonSource photons() const { return {&m_photons, m_photonCount}; }
    uint32_t photonCount() const { return m_photonCount; }
    uint32_t viewCount() const { return uint32_t(m_views.size()); }
    uint32_t mapResolution() const { return m_mapResolution; }
    const std::vector<GpuLightView>& views() const { return m_views; }
    bool usesFloatAtomics() const { return m_floatAtomics; }
    /** Fixed-point scale (units per W) when !usesFloatAtomics(). */
    double fixedScale() const { return m_fixedScale; }

    /** Tests: the photons (blocking read-back). */
    std::vector<GpuPhoton> readPhotons();
    /** Tests: the splatted flux per voxel in W (rgb), x + N (y + N z) order. */
    std::vector<glm::vec3> readVoxelFlux();
    /** Frees the flux accumulators (after shading; the octree path never makes them). */
    void releaseAccumulators() { m_flux.clear(); }
    size_t memoryBytes() const;

private:
    void ensureDenseResources(TechniqueContext& ctx);

    vk::Context& m_vk;
    const vk::GpuScene& m_scene;
    VoxelGrid m_grid;
    uint32_t m_mapResolution;
    std::vector<GpuLightView> m_views;
    uint32_t m_photonCount = 0;
    bool m_floatAtomics = false;
    double m_fixedScale = 1.0;

    vk::Buffer m_viewBuffer;
    vk::Buffer m_photons;
    vk::Image m_positionMap;  // 2D array RGBA32F, one layer per view
    vk::Image m_depth;
    vk::PipelineLayout m_rasterLayout;
    vk::GraphicsPipeline m_raster;
    vk::DescriptorSetLayout m_photonSetLayout;
    vk::DescriptorSet m_photonSet;
    vk::PipelineLayout m_photonLayout;
    vk::ComputePipeline m_photonPipeline;

    // Dense path (created on first use)
    std::vector<vk::Buffer> m_flux;  // 3 planes of N^3 words (float or fixed-point uint)
    vk::Sampler m_nearest;
    vk::DescriptorSetLayout m_splatSetLayout;
    vk::DescriptorSet m_splatSet, m_shadeSet;
    vk::PipelineLayout m_splatLayout;
    vk::ComputePipeline m_splat, m_shade16, m_shade32;
};

}  // namespace vct
}  // namespace gilab
