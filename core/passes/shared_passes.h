#pragma once
/**
 * The passes every technique shares, for one scene and resolution:
 *   gbuffer -> shadow_maps -> direct_light
 * each wrapped in a vk::ScopedGpuPass of that name when a timer is given.
 *
 * Shadow-map policy: the maps are rendered once and reused while lights are static.
 * recordShadows() renders them (the harness calls it during setup so their cost is reported once,
 * as setup time); record() renders them only while they are not valid yet (first frame without a
 * setup call) or after invalidateShadows(). An animated light (updateLights) gets its own map,
 * and only its map, re-rendered by recordShadowUpdates() in the next dynamic frame; a camera
 * move (updateCamera) re-renders only the directional lights' view-fitted cascades.
 */
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <vulkan/vulkan.h>

#include "core/passes/direct_light.h"
#include "core/passes/gbuffer.h"
#include "core/passes/shadow_maps.h"
#include "core/scene/camera.h"

namespace gilab {

namespace vk {
class Context;
class GpuScene;
class GpuTimer;
}  // namespace vk

struct SharedPassSettings {
    ShadowSettings shadow;
    uint32_t areaLightSamples = 16;  // K emitter samples standing in for emissive triangles
    bool areaLightAnalytic = true;   // exact unoccluded irradiance, samples for visibility
};

class SharedPasses {
public:
    SharedPasses(vk::Context& ctx, vk::GpuScene& scene, uint32_t width, uint32_t height,
                 const SharedPassSettings& settings = {});
    SharedPasses(const SharedPasses&) = delete;
    SharedPasses& operator=(const SharedPasses&) = delete;

    /** Renders the shadow maps now (pass "shadow_maps") and marks them valid. */
    void recordShadows(VkCommandBuffer cmd, vk::GpuTimer* timer = nullptr);
    /** One frame: G-buffer, shadow maps if not valid, direct light. */
    void record(VkCommandBuffer cmd, const Camera& camera, vk::GpuTimer* timer = nullptr);
    void invalidateShadows() { m_shadowsValid = false; }
    /**
     * Scene lights `changed` moved (the GpuScene's scene holds their new data and the GpuScene
     * light buffer is updated): updates the pass light table now; their shadow maps, and only
     * theirs, are re-rendered by the next recordShadowUpdates().
     */
    void updateLights(const std::vector<uint32_t>& changed);
    /**
     * The camera of the GpuScene's scene moved: the directional lights' cascades are refitted
     * now and re-rendered by the next recordShadowUpdates().
     */
    void updateCamera();
    /** Re-renders the maps of the lights given to updateLights() and the cascades refitted by
     *  updateCamera() (pass "shadow_maps.update"). */
    void recordShadowUpdates(VkCommandBuffer cmd, vk::GpuTimer* timer = nullptr);
    bool shadowsValid() const { return m_shadowsValid; }

    GBufferPass& gbufferPass() { return *m_gbuffer; }
    GBuffer& gbuffer() { return m_gbuffer->images(); }
    ShadowMaps& shadows() { return *m_shadows; }
    DirectLightPass& directPass() { return *m_direct; }
    /** The direct layer (RGBA32F, GENERAL after record()). */
    vk::Image& direct() { return m_direct->output(); }

    uint32_t width() const { return m_width; }
    uint32_t height() const { return m_height; }
    const SharedPassSettings& settings() const { return m_settings; }
    /** "pass: reason" for every part skipped because the scene lacks it. */
    std::vector<std::string> skippedPasses() const;

private:
    uint32_t m_width;
    uint32_t m_height;
    SharedPassSettings m_settings;
    std::unique_ptr<GBufferPass> m_gbuffer;
    std::unique_ptr<ShadowMaps> m_shadows;
    std::unique_ptr<DirectLightPass> m_direct;
    bool m_shadowsValid = false;
    std::vector<uint32_t> m_staleLights;    // scene lights whose maps await recordShadowUpdates
    std::vector<uint32_t> m_staleCascades;  // scene lights whose cascades await it
};

}  // namespace gilab
