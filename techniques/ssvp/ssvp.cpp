#include "ssvp.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/passes/shadow_maps.h"
#include "core/passes/shared_passes.h"
#include "core/scene/animation.h"
#include "core/scene/scene.h"
#include "core/technique/registry.h"
#include "core/util/error.h"
#include "core/vk/buffer.h"
#include "core/vk/context.h"
#include "core/vpl/paraboloid_maps.h"
#include "core/vpl/rsm.h"
#include "core/vpl/vpl.h"
#include "core/vpl/vpl_math.h"
#include "core/vpl/vpl_shading.h"
#include "ssvp_propagation.h"

namespace gilab {
namespace {

constexpr float kDegToRad = 0.017453292519943295f;

float sceneDiagonal(const Scene& scene) {
    const Bounds& b = scene.caps.bounds;
    return b.valid() ? std::max(glm::length(b.hi - b.lo), 1e-6f) : 1.0f;
}

}  // namespace

/** Every GPU object of one set-up. */
struct SsvpGpu {
    uint32_t light = 0;  // pass light table entry of the main light
    float diagonal = 1.0f;
    vk::Buffer vpls, clusters;
    std::unique_ptr<ReflectiveShadowMap> rsm;
    std::unique_ptr<ParaboloidMaps> maps;
    std::unique_ptr<SsvpPropagation> propagation;
    std::unique_ptr<VplShading> shading;
};

SsvpTechnique::SsvpTechnique() = default;
SsvpTechnique::~SsvpTechnique() = default;

TechniqueInfo SsvpTechnique::describe() {
    TechniqueInfo info;
    info.id = "ssvp";
    info.description =
        "Screen-space VPL propagation: RSM VPLs, K-means clusters with paraboloid maps, "
        "second-bounce VPLs from the maps, interleaved shading (two diffuse bounces)";
    info.citation =
        "V. M. Aranha, M. C. F. Macedo, A. L. Apolinario Jr., \"Screen-space VPL propagation "
        "for real-time indirect lighting\"";
    info.params = ssvpParamSpecs();
    info.indirectBounces = 2;
    info.bouncesParam = "bounces";
    info.checkParams = [](const ParamSet& p) { (void)ssvpSettingsFrom(p); };
    info.supports.pointLights = false;       // no RSM view (a cube RSM is not in the paper)
    info.supports.emissiveSurfaces = false;  // one main light (§II-A)
    return info;
}

SupportResult SsvpTechnique::checkSupport(const Scene& scene, const ParamSet& params) const {
    std::string why;
    if (rsmMainLight(scene, int(params.getInt("light")), &why) < 0) return {false, why};
    return {};
}

void SsvpTechnique::setup(TechniqueContext& ctx) {
    m_gpu.reset();
    m_kmeansConverged = false;
    m_settings = ssvpSettingsFrom(ctx.params);
    const SsvpSettings& s = m_settings;
    std::string why;
    const int light = rsmMainLight(ctx.scene, s.light, &why);
    if (light < 0) throw Error("ssvp: " + why);
    auto gpu = std::make_unique<SsvpGpu>();
    gpu->light = uint32_t(light);  // scene light i is pass light table entry i
    gpu->diagonal = sceneDiagonal(ctx.scene);

    const VkBufferUsageFlags storage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT |
                                       VK_BUFFER_USAGE_TRANSFER_DST_BIT |
                                       VK_BUFFER_USAGE_TRANSFER_SRC_BIT;
    const uint32_t total = s.firstBounceVpls + s.secondBounceVpls;
    gpu->vpls = vk::Buffer(ctx.vk, VkDeviceSize(total) * sizeof(GpuVpl), storage,
                           vk::MemoryUsage::DeviceLocal, ctx.tag("vpls"));
    gpu->clusters = vk::Buffer(ctx.vk, VkDeviceSize(s.mapLayers()) * sizeof(GpuVplCluster), storage,
                               vk::MemoryUsage::DeviceLocal, ctx.tag("clusters"));
    ctx.vk.submitAndWait([&](VkCommandBuffer cmd) {
        vkCmdFillBuffer(cmd, gpu->vpls.handle(), 0, VK_WHOLE_SIZE, 0);
        vkCmdFillBuffer(cmd, gpu->clusters.handle(), 0, VK_WHOLE_SIZE, 0);
    });
    const ShadowMaps& shadows = ctx.shared.shadows();
    gpu->rsm = std::make_unique<ReflectiveShadowMap>(ctx.vk, ctx.gpuScene, shadows.lightBuffer(),
                                                     s.rsmResolution, ctx.tag("gi"));
    ParaboloidSettings ps;
    ps.resolution = s.paraboloidResolution;
    ps.layers = s.mapLayers();
    ps.far = 2.0f * gpu->diagonal;
    gpu->maps =
        std::make_unique<ParaboloidMaps>(ctx.vk, ctx.gpuScene, gpu->clusters, ps, ctx.tag("gi"));
    gpu->propagation = std::make_unique<SsvpPropagation>(ctx.vk, gpu->vpls, gpu->clusters,
                                                         *gpu->maps, ctx.tag("gi"));
    gpu->shading = std::make_unique<VplShading>(ctx.vk, ctx.shared.gbuffer(), gpu->vpls,
                                                gpu->clusters, gpu->maps.get(), ctx.tag("gi"));
    m_gpu = std::move(gpu);
    applySettings(ctx);

    const Light& l = ctx.scene.lights[size_t(light)];
    ctx.note("main light " + std::to_string(light) + " ('" + l.name + "', " +
             (l.type == LightType::Spot ? "spot" : "directional") + "): RSM " +
             std::to_string(s.rsmResolution) + "^2, " + std::to_string(s.clusters) +
             " paraboloid maps of " + std::to_string(s.paraboloidResolution) + "^2");
    if (s.ownMapClusters() > 0)
        ctx.note(
            "second_bounce_visibility = own_maps (ours): " + std::to_string(s.ownMapClusters()) +
            " more paraboloid maps for the second-bounce VPLs");
    if (ctx.scene.lights.size() > 1)
        ctx.skip("bounce from other lights",
                 "the method bounces one main light (§III-A); the others are direct only");
    if (ctx.scene.caps.emissiveTriangleCount > 0)
        ctx.skip("bounce from emissive surfaces", "not a light of the method");
    if (s.bounces < 2) ctx.skip("misc.second_bounce", "bounces = 1: first-bounce VPLs only");
    if (s.ownMapClusters() == 0)
        ctx.skip("paraboloid.second_bounce",
                 "second_bounce_visibility is not own_maps: no maps for second-bounce VPLs");
    ctx.stat("memory_mib",
             double(m_gpu->maps->bytes() + m_gpu->vpls.size() + m_gpu->clusters.size()) /
                 (1024.0 * 1024.0));
}

void SsvpTechnique::applySettings(const TechniqueContext& ctx) {
    m_settings = ssvpSettingsFrom(ctx.params);
    const SsvpSettings& s = m_settings;
    m_gpu->propagation->setSettings(s, m_gpu->diagonal);
    VplShadingSettings v;
    v.interleave = s.interleave;
    v.subsets = s.interleaveSubsets;
    v.clampDistance = s.clampDistance * m_gpu->diagonal;
    v.visibilityBiasTexels = s.visibilityBiasTexels;
    v.blurRadius = s.blurRadius;
    const uint32_t second = s.secondCount();
    // weights = paper: Eq. 6's 1/N over N = N1 + N2 for both bounces (the first-bounce flux is
    // already E A / N1 per VPL, so it is scaled by N1 / N; techniques/ssvp/README.md).
    const float paper = float(s.firstBounceVpls) / float(s.firstBounceVpls + second);
    v.bounceScale = s.paperWeights ? glm::vec2(paper, paper) : glm::vec2(1.0f, 1.0f);
    v.visibility = true;
    m_gpu->shading->setSettings(v);
    m_gpu->maps->setSubdivision(s.maxSubdivision, s.maxEdgeDeg * kDegToRad);
}

void SsvpTechnique::onParamsChanged(TechniqueContext& ctx, const std::vector<std::string>& keys) {
    if (!m_gpu || ctx.params.changesNeedRebuild(keys)) {
        setup(ctx);
        return;
    }
    applySettings(ctx);
}

UpdateKind SsvpTechnique::update(TechniqueContext& ctx, const SceneChanges& changes) {
    if (changes.geometry || !m_gpu) return Technique::update(ctx, changes);
    // Nothing is cached between frames except the K-means warm start: the RSM is rendered from
    // the updated pass light table in the next render().
    return UpdateKind::None;
}

void SsvpTechnique::render(TechniqueContext& ctx, VkCommandBuffer cmd, FrameTargets& targets) {
    if (!m_gpu) throw Error("ssvp: render() before setup()");
    SsvpGpu& g = *m_gpu;
    const SsvpSettings& s = m_settings;
    const PassLight& light = ctx.shared.shadows().lights()[g.light];
    {
        PassScope pass(ctx, cmd, "misc.rsm");
        g.rsm->record(cmd, light, g.light);
    }
    {
        PassScope pass(ctx, cmd, "misc.vpl_sample");
        g.rsm->recordVpls(cmd, g.vpls, 0, s.firstBounceVpls, vpl::cranleyPattersonShift(s.seed));
    }
    {
        PassScope pass(ctx, cmd, "misc.kmeans");
        g.propagation->recordClustering(cmd, SsvpRange::First);
    }
    {
        PassScope pass(ctx, cmd, "paraboloid.maps");
        g.maps->record(cmd, 0, s.clusters);
    }
    {
        PassScope pass(ctx, cmd, "misc.map_members");
        g.propagation->recordMembers(cmd, SsvpRange::First);
    }
    if (s.secondCount() > 0) {
        PassScope pass(ctx, cmd, "misc.second_bounce");
        g.propagation->recordSecondBounce(cmd);
    }
    if (s.ownMapClusters() > 0) {
        // own_maps (ours): the second-bounce VPLs get clusters and maps of their own, so the
        // gather tests them as it tests the first bounce (layers C .. C + C2).
        {
            PassScope pass(ctx, cmd, "misc.second_kmeans");
            g.propagation->recordClustering(cmd, SsvpRange::Second);
        }
        {
            PassScope pass(ctx, cmd, "paraboloid.second_bounce");
            g.maps->record(cmd, s.clusters, s.ownMapClusters());
        }
        PassScope pass(ctx, cmd, "misc.second_map_members");
        g.propagation->recordMembers(cmd, SsvpRange::Second);
    }
    {
        PassScope pass(ctx, cmd, "shade.gather");
        const uint32_t count = s.firstBounceVpls + s.secondCount();
        // Sets: the N1 RSM VPLs, then each cluster's M disk VPLs (§III-A, §III-C).
        g.shading->recordGather(cmd, count, s.firstBounceVpls, std::max(s.perCluster(), 1u));
    }
    PassScope pass(ctx, cmd, "shade.blur");
    g.shading->recordResolve(cmd, targets.indirect);
}

void SsvpTechnique::frameFinished(TechniqueContext& ctx) {
    if (!m_gpu) return;
    const VplClampStats clamp = m_gpu->shading->readClampStats();
    ctx.stat("clamped_energy_percent", clamp.removedPercent());
    ctx.stat("clamped_irradiance_mean",
             clamp.pixels > 0 ? clamp.removedIrradiance / clamp.pixels : 0.0);
    const SsvpKmeansState k = m_gpu->propagation->readState(SsvpRange::First);
    ctx.stat("kmeans_iterations", k.iterations);
    ctx.stat("kmeans_converged", k.converged ? 1.0 : 0.0);
    m_kmeansConverged = k.converged;
    ctx.stat("kmeans_reseeded", k.reseeded);
    ctx.stat("active_clusters", k.active);
    ctx.stat("valid_first_bounce_vpls", k.assigned);
    const SsvpMemberStats members = m_gpu->propagation->readMemberStats(SsvpRange::First);
    ctx.stat("map_sees_member_flux_percent", members.seenPercent);
    ctx.stat("shading_map_sees_member_flux_percent", members.seenAfterPercent);
    ctx.stat("moved_member_flux_percent", members.movedPercent);
    if (m_settings.ownMapClusters() > 0) {
        const SsvpKmeansState k2 = m_gpu->propagation->readState(SsvpRange::Second);
        ctx.stat("second_kmeans_iterations", k2.iterations);
        ctx.stat("second_kmeans_converged", k2.converged ? 1.0 : 0.0);
        ctx.stat("second_active_clusters", k2.active);
        ctx.stat("valid_second_bounce_vpls", k2.assigned);
        m_kmeansConverged = m_kmeansConverged && k2.converged;
        const SsvpMemberStats m2 = m_gpu->propagation->readMemberStats(SsvpRange::Second);
        ctx.stat("second_map_sees_member_flux_percent", m2.seenPercent);
        ctx.stat("second_shading_map_sees_member_flux_percent", m2.seenAfterPercent);
    }
}

std::vector<DebugView> SsvpTechnique::debugViews() {
    if (!m_gpu) return {};
    return {{"irradiance", &m_gpu->shading->irradiance()}};
}

bool SsvpTechnique::readVplSet(VplSet& out) {
    if (!m_gpu) return false;
    const SsvpSettings& s = m_settings;
    const uint32_t count = s.firstBounceVpls + s.secondCount();
    out.vpls = m_gpu->vpls.downloadVector<GpuVpl>(count);
    const VplShadingSettings& v = m_gpu->shading->settings();
    out.clampDistance = v.clampDistance;
    out.bounceScale = v.bounceScale;
    return true;
}

GILAB_REGISTER_TECHNIQUE(SsvpTechnique)

}  // namespace gilab
