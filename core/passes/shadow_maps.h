#pragma once
/**
 * Shadow maps for every light of the pass light table (core/passes/pass_light.h): the scene's
 * punctual lights and the emitter samples that stand in for emissive triangles.
 *
 * Each map stores the LINEAR distance from the light (R32F colour; a D32 buffer only orders the
 * fragments, reversed-Z with an infinite far plane, shared by all renders):
 *   spot (outer cone <= 85 deg)  2D perspective, fov = 2 * outer + 5 deg (<= 170 deg)
 *   directional                  2D orthographic fitted to the scene's bounding sphere; stores the
 *                                distance along the light direction from the sphere's entry plane;
 *                                plus `cascades` 2D maps fitted to the camera's view
 *                                (shadow_cascades.h), used by surface receivers
 *   point, spot > 85 deg         cube (6 faces, one render each; Vulkan cube face axes)
 *   emitter sample               cube at areaResolution; surfaces in the emitter's own plane are
 *                                not rendered (they cannot occlude the emitter's hemisphere)
 * All 2D maps share one 2D-array image, the point cubes one cube-array image and the sample cubes
 * another. Categories the scene lacks are not built (a 1x1 placeholder keeps the descriptor
 * valid) and are listed by skippedPasses(). Lookups: shaders/common/shadow.glsl.
 * Every map is in SHADER_READ_ONLY_OPTIMAL outside record() (cleared to "no occluder" at
 * construction, so lookups before the first record() see everything lit).
 * The light table entry of scene light i is i; ShadowMaps writes it into GpuLight.cone.z.
 */
#include <cstdint>
#include <string>
#include <vector>

#include <vulkan/vulkan.h>
#include <glm/glm.hpp>

#include "core/passes/emitter_samples.h"
#include "core/passes/pass_light.h"
#include "core/vk/buffer.h"
#include "core/vk/descriptors.h"
#include "core/vk/image.h"
#include "core/vk/pipeline.h"
#include "core/vk/sampler.h"

namespace gilab {

struct Light;

namespace vk {
class Context;
class GpuScene;
}  // namespace vk

/**
 * Lookup settings of surface receivers (the direct pass: points of rasterised triangles). Bias
 * terms are in shadow-map texels at the receiver (texel = the map's texel footprint at the
 * receiver's distance), so they hold for any scene scale and resolution. See
 * docs/shared_passes.md for how the defaults were measured against the path tracer.
 */
struct ShadowSettings {
    uint32_t resolution = 1024;     // 2D maps, cascades and point-light cubes, texels per side
    uint32_t areaResolution = 256;  // emitter-sample cubes, texels per side
    int pcfRadius = 0;              // (2r+1)^2 taps; 0 = hard shadows
    float constantBias = 0.5f;      // texels
    float slopeBias = 0.0f;         // texels per unit tan(theta)
    float normalOffset = 0.0f;      // texels per (pcfRadius + 1), receiver moved along its normal
    bool receiverPlane = true;      // compare each texel with the receiver's plane along its ray
    uint32_t cascades = 4;          // view-fitted maps per directional light (0 = none)
    float cascadeSplit = 0.5f;      // split scheme: 0 uniform, 1 logarithmic
    bool cascadeSnap = true;        // stable cascade texels (shadow_cascades.h CascadeSettings)
    float cascadeBlend = 0.0f;      // band at each cascade's border, a fraction of its half-size,
                                    // where the visibility fades into the next cascade's
    bool enabled = true;            // false: no maps at all, visibility = 1
};

/**
 * Settings of volume receivers (voxel centres: shadowVisibility in shadow.glsl), which have no
 * triangle plane: the offset-and-slope test with x constant 1, y slope 1 (texels), z normal
 * offset 1 (texels per PCF radius + 1), w PCF radius 1.
 */
inline constexpr glm::vec4 kVolumeShadowBias{1.0f, 1.0f, 1.0f, 1.0f};

class ShadowMaps {
public:
    static constexpr VkFormat kDistanceFormat = VK_FORMAT_R32_SFLOAT;
    static constexpr VkFormat kDepthFormat = VK_FORMAT_D32_SFLOAT;
    /** Bindings used by shadow.glsl, starting at SHADOW_BINDING. */
    static constexpr uint32_t kBindingCount = 4;

    /**
     * Builds the light table (uploads it), the emitter samples and the images. The cascades are
     * fitted to the GpuScene's scene camera at this aspect (width / height).
     */
    ShadowMaps(vk::Context& ctx, vk::GpuScene& scene, const ShadowSettings& settings,
               uint32_t areaLightSamples, float aspect);
    ShadowMaps(const ShadowMaps&) = delete;
    ShadowMaps& operator=(const ShadowMaps&) = delete;

    /**
     * Renders every map (one draw of the scene per 2D map or cube face), or only the maps of
     * the pass lights in `onlyLights` (an animated scene re-renders the lights that moved).
     */
    void record(VkCommandBuffer cmd, const std::vector<uint32_t>* onlyLights = nullptr,
                bool cascadesOnly = false);
    /**
     * Recomputes the table entries and map matrices of scene lights `changed` from the
     * GpuScene's scene (same count and types; each keeps its map slot) and re-uploads the
     * table. Their maps are stale until record(cmd, &changed).
     */
    void updateSceneLights(const std::vector<uint32_t>& changed);
    /**
     * Refits the cascades to the GpuScene's scene camera (it moved) and re-uploads the table.
     * Returns the scene lights whose cascades are stale until record(cmd, &lights, true).
     */
    std::vector<uint32_t> updateCamera();

    const std::vector<PassLight>& lights() const { return m_lights; }
    uint32_t lightCount() const { return uint32_t(m_lights.size()); }
    const vk::Buffer& lightBuffer() const { return m_lightBuffer; }
    const std::vector<EmitterSample>& emitterSamples() const { return m_samples; }
    /** The emissive triangles (4 vec4 each: p0 + w two-sided, p1, p2, radiance), built with the
     *  emitter samples (a 1-entry placeholder when there are none). */
    const vk::Buffer& emitterPolygonBuffer() const { return m_polygonBuffer; }
    uint32_t emitterPolygonCount() const { return m_polygonCount; }
    const ShadowSettings& settings() const { return m_settings; }
    /** The cascade entries (after lights() in the buffer), in light order. */
    const std::vector<PassLight>& cascadeEntries() const { return m_cascades; }
    /** Number of scene lights (the first entries of lights()). */
    uint32_t sceneLightCount() const { return m_sceneLightCount; }
    /** Map renders (2D layers + cube faces) per record(). */
    uint32_t renderCount() const { return uint32_t(m_jobs.size()); }
    /** "shadow.cube: scene has no point lights" etc. */
    const std::vector<std::string>& skippedPasses() const { return m_skipped; }

    vk::Image& maps2D() { return m_maps2D; }
    vk::Image& cubes() { return m_cubes; }
    vk::Image& areaCubes() { return m_areaCubes; }

    /** The 4 bindings of shadow.glsl (light table, 2D maps, cubes, sample cubes). */
    static std::vector<vk::DescriptorBinding> descriptorBindings(uint32_t firstBinding,
                                                                 VkShaderStageFlags stages);
    void writeDescriptors(vk::DescriptorSet& set, uint32_t firstBinding);

private:
    /** One render: a 2D layer or one cube face. The push block mirrors shadow_pc.glsl. */
    struct Job {
        ShadowKind kind = kShadowNone;
        uint32_t layer = 0;    // layer of the target image (6 * cube + face for cubes)
        uint32_t light = 0;    // index into lights()
        bool cascade = false;  // a view-fitted cascade of `light`
        struct Push {
            glm::mat4 viewProj{1.0f};
            glm::vec4 origin{0.0f};  // w 1 = orthographic
            glm::vec4 direction{0.0f};
            glm::vec4 skipPlane{0.0f};  // emitter plane (normal, offset)
            glm::vec4 params{0.0f};     // x skip-plane half thickness
        } push;
    };
    static_assert(sizeof(Job::Push) == 128);

    /** Scene bounds the directional maps are fitted to, and the near plane. */
    struct Frame {
        glm::vec3 center{0.0f};
        float radius = 1.0f;
        float nearZ = 1e-3f;
    };
    Frame sceneFrame() const;
    /** The table entry of scene light `l` (index `index`) with its map in `slot` of `kind`
     *  (kShadowNone: no map), appending its render jobs to `jobs` and, for a directional light
     *  with cascades, writing them to m_cascades from its `cascades.x` entry on. */
    PassLight sceneLightEntry(const Light& l, uint32_t index, ShadowKind kind, uint32_t slot,
                              std::vector<Job>& jobs);
    /** Fits light `index`'s cascades (entries from `firstEntry`, layers from `firstLayer`). */
    void fitCascades(const PassLight& light, uint32_t index, uint32_t firstEntry,
                     uint32_t firstLayer, std::vector<Job>& jobs);
    void uploadTable();
    void addCubeJobs(const PassLight& light, uint32_t lightIndex, ShadowKind kind, uint32_t cube,
                     const Job::Push& base, float nearZ, std::vector<Job>& jobs) const;
    void buildLightTable(const vk::GpuScene& scene, uint32_t areaLightSamples);
    void createImages();

    vk::Context& m_ctx;
    vk::GpuScene& m_scene;
    ShadowSettings m_settings;
    std::vector<PassLight> m_lights;
    std::vector<PassLight> m_cascades;  // cascade entries, after m_lights in the buffer
    float m_aspect = 1.0f;
    std::vector<EmitterSample> m_samples;
    std::vector<Job> m_jobs;
    std::vector<std::string> m_skipped;
    uint32_t m_sceneLightCount = 0;
    uint32_t m_layers2D = 0;
    uint32_t m_cubeCount = 0;
    uint32_t m_areaCubeCount = 0;

    vk::Buffer m_lightBuffer;
    vk::Buffer m_polygonBuffer;
    uint32_t m_polygonCount = 0;
    vk::Image m_maps2D;
    vk::Image m_cubes;
    vk::Image m_areaCubes;
    vk::Image m_depth;
    vk::Sampler m_sampler;
    vk::PipelineLayout m_layout;
    vk::GraphicsPipeline m_pipeline;
};

}  // namespace gilab
