#include "core/passes/shared_passes.h"

#include <algorithm>
#include <optional>

#include "core/gpu/gpu_scene.h"
#include "core/vk/context.h"
#include "core/vk/timer.h"

namespace gilab {

SharedPasses::SharedPasses(vk::Context& ctx, vk::GpuScene& scene, uint32_t width, uint32_t height,
                           const SharedPassSettings& settings)
    : m_width(width), m_height(height), m_settings(settings) {
    m_gbuffer = std::make_unique<GBufferPass>(ctx, scene, width, height);
    m_shadows = std::make_unique<ShadowMaps>(ctx, scene, settings.shadow, settings.areaLightSamples,
                                             float(width) / float(std::max(height, 1u)));
    m_direct = std::make_unique<DirectLightPass>(ctx, scene, m_gbuffer->images(), *m_shadows,
                                                 settings.areaLightAnalytic);
}

void SharedPasses::recordShadows(VkCommandBuffer cmd, vk::GpuTimer* timer) {
    std::optional<vk::ScopedGpuPass> scope;
    if (timer) scope.emplace(*timer, cmd, "shadow_maps");
    m_shadows->record(cmd);
    m_shadowsValid = true;
}

void SharedPasses::updateLights(const std::vector<uint32_t>& changed) {
    if (changed.empty()) return;
    m_shadows->updateSceneLights(changed);
    m_staleLights.insert(m_staleLights.end(), changed.begin(), changed.end());
}

void SharedPasses::updateCamera() {
    for (uint32_t light : m_shadows->updateCamera())
        if (std::find(m_staleCascades.begin(), m_staleCascades.end(), light) ==
            m_staleCascades.end())
            m_staleCascades.push_back(light);
}

void SharedPasses::recordShadowUpdates(VkCommandBuffer cmd, vk::GpuTimer* timer) {
    if (m_staleLights.empty() && m_staleCascades.empty()) return;
    std::optional<vk::ScopedGpuPass> scope;
    if (timer) scope.emplace(*timer, cmd, "shadow_maps.update");
    if (!m_staleLights.empty()) m_shadows->record(cmd, &m_staleLights);
    // Cascades of lights that did not move but were refitted to the new camera
    std::vector<uint32_t> cascadesOnly;
    for (uint32_t light : m_staleCascades)
        if (std::find(m_staleLights.begin(), m_staleLights.end(), light) == m_staleLights.end())
            cascadesOnly.push_back(light);
    if (!cascadesOnly.empty()) m_shadows->record(cmd, &cascadesOnly, true);
    m_staleLights.clear();
    m_staleCascades.clear();
}

void SharedPasses::record(VkCommandBuffer cmd, const Camera& camera, vk::GpuTimer* timer) {
    {
        std::optional<vk::ScopedGpuPass> scope;
        if (timer) scope.emplace(*timer, cmd, "gbuffer");
        m_gbuffer->record(cmd, camera);
    }
    if (!m_shadowsValid) recordShadows(cmd, timer);
    {
        std::optional<vk::ScopedGpuPass> scope;
        if (timer) scope.emplace(*timer, cmd, "direct_light");
        m_direct->record(cmd, camera);
    }
}

std::vector<std::string> SharedPasses::skippedPasses() const {
    return m_shadows->skippedPasses();
}

}  // namespace gilab
