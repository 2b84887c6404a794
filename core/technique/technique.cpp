#include "core/technique/technique.h"

#include <chrono>

#include "core/scene/animation.h"

#include "core/scene/scene.h"
#include "core/vk/context.h"
#include "core/vk/timer.h"

namespace gilab {

std::string TechniqueContext::tag(const std::string& resource) const {
    return techniqueId + "/" + resource;
}

void TechniqueContext::skip(const std::string& pass, const std::string& reason) const {
    if (skipped) skipped->push_back(techniqueId + "/" + pass + ": " + reason);
}

void TechniqueContext::note(const std::string& text) const {
    if (notes) notes->push_back(techniqueId + ": " + text);
}

void TechniqueContext::stat(const std::string& name, double value) const {
    if (!stats) return;
    for (auto& [n, v] : *stats) {
        if (n == name) {
            v = value;
            return;
        }
    }
    stats->emplace_back(name, value);
}

void TechniqueContext::submitTimed(const std::function<void(VkCommandBuffer)>& record) const {
    vk.submitAndWait([&](VkCommandBuffer cmd) {
        if (timer) timer->reset(cmd);
        record(cmd);
    });
    if (!timer || !setupTimes) return;
    for (const vk::PassTime& p : timer->resolve())
        setupTimes->push_back({p.name, p.gpuMs});
}

void TechniqueContext::timeCpu(const std::string& name, const std::function<void()>& work) const {
    const auto start = std::chrono::steady_clock::now();
    work();
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    if (setupTimes) setupTimes->push_back({techniqueId + "/" + name, 0.0, ms});
}

PassScope::PassScope(const TechniqueContext& ctx, VkCommandBuffer cmd, const std::string& name)
    : m_timer(ctx.timer), m_cmd(cmd) {
    if (m_timer) m_timer->begin(cmd, ctx.techniqueId + "/" + name);
}

PassScope::~PassScope() {
    if (m_timer) m_timer->end(m_cmd);
}

int claimedBounces(const TechniqueInfo& info, const ParamSet& params) {
    if (info.bouncesParam.empty()) return info.indirectBounces;
    return params.getInt(info.bouncesParam);
}

SupportResult Technique::checkSupport(const Scene& scene, const ParamSet&) const {
    const FeatureSupport& s = m_info.supports;
    const SceneCaps& caps = scene.caps;
    auto no = [](const std::string& what) { return SupportResult{false, what}; };
    if (caps.hasPointLights && !s.pointLights) return no("does not support point lights");
    if (caps.hasSpotLights && !s.spotLights) return no("does not support spot lights");
    if (caps.hasDirectionalLights && !s.directionalLights)
        return no("does not support directional lights");
    if (caps.hasEmissive && !s.emissiveSurfaces)
        return no("does not support emissive surfaces as light sources");
    return {};
}

void Technique::onParamsChanged(TechniqueContext& ctx, const std::vector<std::string>& keys) {
    if (ctx.params.changesNeedRebuild(keys)) setup(ctx);
}

UpdateKind Technique::update(TechniqueContext& ctx, const SceneChanges& changes) {
    if (!changes.any()) return UpdateKind::None;
    setup(ctx);
    return UpdateKind::FullRebuild;
}

const char* updateKindName(UpdateKind kind) {
    switch (kind) {
        case UpdateKind::None:
            return "none";
        case UpdateKind::Incremental:
            return "incremental";
        case UpdateKind::FullRebuild:
            return "full rebuild";
    }
    return "?";
}

}  // namespace gilab
