#include "ddgi.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "core/passes/shadow_maps.h"
#include "core/passes/shared_passes.h"
#include "core/rt/gpu_bvh.h"
#include "core/scene/animation.h"
#include "core/scene/scene.h"
#include "core/technique/registry.h"
#include "core/util/error.h"
#include "ddgi_volume.h"

namespace gilab {
namespace {

/** Cold-start ramp: until the probes first settle, update k blends with
 *  min(alpha, k / (k + kRampFrames)), a mean over about the last k / kRampFrames updates, so the
 *  first updates (fewer bounces fed back) are forgotten fast (the remaining error falls like
 *  k^-((1 - rho) kRampFrames) for albedo rho); from then on, alpha. */
constexpr float kRampFrames = 4.0f;
/** Settled: at least this many updates, the last kQuietUpdates of them with an estimated
 *  remaining change below settle_tolerance (one quiet update can be noise); the change is taken
 *  over windows of kWindow updates and the tail's ratio per window capped at kMaxRatio. */
constexpr uint32_t kMinSettleUpdates = 8;
constexpr int kQuietUpdates = 3;
constexpr size_t kWindow = 4;
constexpr double kMaxRatio = 0.9;

}  // namespace

DdgiTechnique::DdgiTechnique() = default;
DdgiTechnique::~DdgiTechnique() = default;

TechniqueInfo DdgiTechnique::describe() {
    TechniqueInfo info;
    info.id = "ddgi";
    info.description =
        "Dynamic diffuse GI: ray-traced irradiance probes (octahedral irradiance + distance "
        "moments, hysteresis, Chebyshev visibility), relocation and classification";
    info.citation =
        "Z. Majercik, J.-P. Guertin, D. Nowrouzezahrai, M. McGuire, \"Dynamic Diffuse Global "
        "Illumination with Ray-Traced Irradiance Fields\", JCGT 8(2), 2019; Z. Majercik, "
        "A. Marrs, J. Spjut, M. McGuire, \"Scaling Probe-Based Real-Time Dynamic Global "
        "Illumination for Production\", JCGT 10(2), 2021";
    info.params = ddgiParamSpecs();
    info.indirectBounces = kAllBounces;
    info.bouncesParam = "bounces";
    info.checkParams = [](const ParamSet& p) { (void)ddgiSettingsFrom(p); };
    return info;
}

void DdgiTechnique::resetSettle() {
    m_settled = false;
    m_means.clear();
    m_quietUpdates = 0;
}

void DdgiTechnique::setup(TechniqueContext& ctx) {
    const DdgiSettings s = ddgiSettingsFrom(ctx.params);
    m_volume.reset();
    m_volume = std::make_unique<DdgiVolume>(ctx, s);
    ctx.submitTimed([&](VkCommandBuffer cmd) { m_volume->recordClear(cmd); });
    m_updates = 0;
    m_updateIndex = 0;
    m_eventFramesLeft = 0;
    m_rampDone = false;
    resetSettle();

    const DdgiGrid& g = m_volume->grid();
    char text[256];
    std::snprintf(text, sizeof text,
                  "probe grid %dx%dx%d (%u probes), spacing %.3g x %.3g x %.3g m, %d rays per "
                  "probe (%d fixed), texels %d + 2 / %d + 2",
                  g.counts.x, g.counts.y, g.counts.z, g.probeCount(), g.spacing.x, g.spacing.y,
                  g.spacing.z, s.raysPerProbe, s.fixedRays(), s.irradianceTexels, s.distanceTexels);
    ctx.note(text);
    const rt::BvhStats& b = m_volume->bvh().stats();
    std::snprintf(text, sizeof text,
                  "GPU ray tracer: BVH of %u triangles (%u references), %u nodes, depth %u, "
                  "built in %.1f ms",
                  b.triangles, b.triangleRefs, b.nodes, b.depth, b.buildMs);
    ctx.note(text);
    ctx.note(
        "no light is precomputed: every frame traces, blends and gathers, so a light or "
        "camera change costs what a static frame does; the probes converge over updates "
        "(hysteresis " +
        ctx.params.getText("hysteresis") + ")");
    ctx.stat("probes", double(g.probeCount()));
    ctx.stat("rays_per_update", double(m_volume->raysPerUpdate()));
    ctx.stat("bvh_nodes", double(b.nodes));
    if (!s.relocation) ctx.skip("probe_relocation", "relocation = false");
    if (!s.classification) ctx.skip("probe_classification", "classification = false");
    if (!ctx.scene.caps.hasEmissive)
        ctx.skip("emitter samples at probe-ray hits", "scene has no emitters");
    if (s.emissionInProbes)
        ctx.note(
            "emission_in_probes = true: emitters' light reaches the pixels twice (direct "
            "layer and probes)");
}

UpdateKind DdgiTechnique::update(TechniqueContext& ctx, const SceneChanges& changes) {
    if (!m_volume) return Technique::update(ctx, changes);
    const DdgiSettings s = ddgiSettingsFrom(ctx.params);
    if (!changes.lights.empty() || changes.geometry) {
        m_eventFramesLeft = s.eventFrames;  // G3D onGlobalLightChange
        resetSettle();
    }
    if (changes.geometry) {
        ctx.timeCpu("bvh_rebuild", [&] { m_volume->rebuildBvh(ctx.scene); });
        return UpdateKind::Incremental;
    }
    // Lights and camera: the next update's probe rays and the gather see them; nothing to redo
    return UpdateKind::None;
}

float DdgiTechnique::nextHysteresis(const DdgiSettings& s) const {
    float alpha = s.hysteresis;
    if (s.warmStart == DdgiWarmStart::Ramp && !m_rampDone)
        alpha = std::min(alpha, float(m_updates) / float(m_updates + kRampFrames));
    else if (m_updates == 0)
        alpha = 0.0f;
    if (m_eventFramesLeft > 0) alpha *= 0.5f;
    return alpha;
}

void DdgiTechnique::render(TechniqueContext& ctx, VkCommandBuffer cmd, FrameTargets& targets) {
    if (!m_volume) throw Error("ddgi: render() before setup()");
    const DdgiSettings s = ddgiSettingsFrom(ctx.params);
    DdgiFrameInputs in;
    in.hysteresis = nextHysteresis(s);
    in.updateIndex = m_updateIndex;
    in.camera = ctx.scene.camera.position;
    m_volume->setFrame(s, in);
    m_volume->setIndirectTarget(targets.indirect);
    m_volume->recordUpdate(ctx, cmd);
    m_volume->recordGather(ctx, cmd);
    ++m_updates;
    ++m_updateIndex;
    if (m_eventFramesLeft > 0) --m_eventFramesLeft;
}

void DdgiTechnique::frameFinished(TechniqueContext& ctx) {
    if (!m_volume) return;
    const DdgiSettings s = ddgiSettingsFrom(ctx.params);
    ctx.stat("updates", double(m_updates));
    if (s.relocation || s.classification) {
        const std::vector<glm::vec4> probes = m_volume->readProbeData();
        size_t relocated = 0, inactive = 0;
        for (const glm::vec4& p : probes) {
            if (glm::vec3(p) != glm::vec3(0.0f)) ++relocated;
            if (p.w > 0.5f) ++inactive;
        }
        if (s.relocation) ctx.stat("probes_relocated", double(relocated));
        if (s.classification) ctx.stat("probes_inactive", double(inactive));
    }
    ctx.stat("settled", m_settled ? 1.0 : 0.0);
    if (m_settled) return;
    // Convergence: the change of the mean irradiance over the last kWindow updates, c1, against
    // the window before, c0; a geometric tail with ratio r = c1 / c0 (at most kMaxRatio, so the
    // flicker of a converged volume does not read as an endless tail) leaves c1 r / (1 - r)
    const double mean = m_volume->meanIrradiance();
    if (!std::isfinite(mean)) throw Error("ddgi: the probe irradiance is not finite");
    m_means.push_back(mean);
    const size_t k = m_means.size();
    if (k > 2 * kWindow) {
        const double c1 = std::abs(m_means[k - 1] - m_means[k - 1 - kWindow]);
        const double c0 = std::abs(m_means[k - 1 - kWindow] - m_means[k - 1 - 2 * kWindow]);
        const double r = c0 > 0.0 ? std::min(c1 / c0, kMaxRatio) : (c1 > 0.0 ? kMaxRatio : 0.0);
        double remaining = mean > 0.0 ? c1 * r / (1.0 - r) / mean : 0.0;  // unlit: nothing to do
        remaining = std::max(remaining, mean > 0.0 ? c1 / mean : 0.0);
        ctx.stat("settle_remaining", remaining);
        m_quietUpdates = remaining < s.settleTolerance ? m_quietUpdates + 1 : 0;
        if (m_updates >= kMinSettleUpdates && m_quietUpdates >= kQuietUpdates) {
            m_settled = true;
            m_rampDone = true;
            ctx.stat("settled", 1.0);
            ctx.stat("settle_updates", double(m_updates));
        }
    }
}

GILAB_REGISTER_TECHNIQUE(DdgiTechnique)

}  // namespace gilab
