#include "topovpl.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "core/passes/shadow_maps.h"
#include "core/passes/shared_passes.h"
#include "core/scene/animation.h"
#include "core/scene/scene.h"
#include "core/technique/registry.h"
#include "core/util/error.h"
#include "core/vk/buffer.h"
#include "core/vk/context.h"
#include "core/vpl/rsm.h"
#include "core/vpl/vpl.h"
#include "core/vpl/vpl_math.h"
#include "gate_lighting.h"
#include "pixel_clusters.h"
#include "scene_topology.h"
#include "topology_cache.h"
#include "topology_export.h"

namespace gilab {
namespace {

float sceneDiagonal(const Scene& scene) {
    const Bounds& b = scene.caps.bounds;
    return b.valid() ? std::max(glm::length(b.hi - b.lo), 1e-6f) : 1.0f;
}

topo::TopologySettings topologySettings(const TopovplSettings& s) {
    topo::TopologySettings t;
    t.resolution = s.voxelResolution;
    t.alpha = s.alphaPercent / 100.0f;
    t.mergeVisible = s.mergeVisible;
    t.mergeVisibility = s.mergeVisibility;
    t.gatePlacement =
        s.gateAtBottleneck ? topo::GatePlacement::Bottleneck : topo::GatePlacement::Midpoint;
    t.clusterRule = s.chainedClusters ? topo::ClusterRule::Chained : topo::ClusterRule::Seed;
    t.ballMetric = s.chessboardBalls ? topo::BallMetric::Chessboard : topo::BallMetric::Euclidean;
    t.coverageSplit = s.splitMostUncovered ? topo::CoverageSplit::Most : topo::CoverageSplit::First;
    t.skeletonFilter =
        s.lifespanFilter ? topo::SkeletonFilter::Lifespan : topo::SkeletonFilter::SpurPrune;
    return t;
}

/** The topology from the disk cache, or built (timed step by step) and stored. */
topo::SceneTopology acquireTopology(TechniqueContext& ctx, const TopovplSettings& s) {
    const topo::TopologySettings ts = topologySettings(s);
    const std::string key = topo::topologyKey(ctx.scene, ts);
    const auto dir = topo::defaultTopologyCacheDir();
    if (s.useCache) {
        std::string why;
        std::optional<topo::SceneTopology> cached = topo::loadTopology(dir, key, &why);
        if (cached) {
            ctx.note("topology read from the cache: " + topo::topologyCacheFile(dir, key).string());
            ctx.stat("topology_cache_hit", 1.0);
            return std::move(*cached);
        }
        if (!why.empty()) ctx.note("topology cache entry not used: " + why);
    }
    ctx.stat("topology_cache_hit", 0.0);
    topo::SceneTopology t =
        topo::buildSceneTopology(ctx.vk, ctx.gpuScene, ctx.scene, ts,
                                 [&](const std::string& name, const std::function<void()>& work) {
                                     ctx.timeCpu(name, work);
                                 });
    if (s.useCache) {
        topo::storeTopology(dir, key, t);
        ctx.note("topology stored in the cache: " + topo::topologyCacheFile(dir, key).string());
    }
    return t;
}

float gateRadius(const topo::WorldGate& g, const TopovplSettings& s) {
    const float r = s.gateRadius == GateRadiusRule::Neck  ? g.radiusNeck
                    : s.gateRadius == GateRadiusRule::Min ? std::min(g.radiusA, g.radiusB)
                    : s.gateRadius == GateRadiusRule::Max ? std::max(g.radiusA, g.radiusB)
                                                          : 0.5f * (g.radiusA + g.radiusB);
    return r * s.gateRadiusScale;
}

topo::GateTable gateTable(const topo::SceneTopology& t, const TopovplSettings& s) {
    topo::GateTable table;
    table.clusterCount = t.segmentation.clusterCount;
    std::vector<std::vector<uint32_t>> lists(table.clusterCount);
    for (size_t i = 0; i < t.gates.size(); ++i) {
        const topo::WorldGate& g = t.gates[i];
        table.gates.push_back({glm::vec4(g.centre, gateRadius(g, s)), glm::vec4(g.normal, 0.0f),
                               glm::uvec4(g.clusterA, g.clusterB, 0u, 0u)});
        lists[g.clusterA].push_back(uint32_t(i));
        if (g.clusterB != g.clusterA) lists[g.clusterB].push_back(uint32_t(i));
    }
    table.clusterStart.push_back(0);
    for (const auto& l : lists) {
        table.clusterGates.insert(table.clusterGates.end(), l.begin(), l.end());
        table.clusterStart.push_back(uint32_t(table.clusterGates.size()));
    }
    return table;
}

}  // namespace

/** Every GPU object of one set-up. */
struct TopovplGpu {
    uint32_t light = 0;  // pass light table entry of the main light
    float diagonal = 1.0f;
    topo::SceneTopology topology;
    vk::Buffer vpls;
    std::unique_ptr<ReflectiveShadowMap> rsm;
    std::unique_ptr<topo::PixelClusters> pixels;
    std::unique_ptr<topo::GateLighting> lighting;
};

TopovplTechnique::TopovplTechnique() = default;
TopovplTechnique::~TopovplTechnique() = default;

TechniqueInfo TopovplTechnique::describe() {
    TechniqueInfo info;
    info.id = "topovpl";
    info.description =
        "Topological VPLs: RSM VPLs whose visibility is the precomputed skeleton of the empty "
        "space (clusters and gates), clustered shading (one diffuse bounce)";
    info.citation =
        "S. Noel, V. Biri, \"Real-Time Global Illumination using Topological Information\", "
        "GSTF Journal on Computing 4(1), 2014";
    info.params = topovplParamSpecs();
    info.indirectBounces = 1;
    info.checkParams = [](const ParamSet& p) { (void)topovplSettingsFrom(p); };
    info.supports.pointLights = false;       // no RSM view
    info.supports.emissiveSurfaces = false;  // VPLs of one main light
    return info;
}

SupportResult TopovplTechnique::checkSupport(const Scene& scene, const ParamSet& params) const {
    std::string why;
    if (rsmMainLight(scene, int(params.getInt("light")), &why) < 0) return {false, why};
    if (!scene.caps.bounds.valid()) return {false, "the scene has no geometry to voxelize"};
    return {};
}

void TopovplTechnique::setup(TechniqueContext& ctx) {
    m_gpu.reset();
    m_settings = topovplSettingsFrom(ctx.params);
    const TopovplSettings& s = m_settings;
    std::string why;
    const int light = rsmMainLight(ctx.scene, s.light, &why);
    if (light < 0) throw Error("topovpl: " + why);
    auto gpu = std::make_unique<TopovplGpu>();
    gpu->light = uint32_t(light);
    gpu->diagonal = sceneDiagonal(ctx.scene);
    gpu->topology = acquireTopology(ctx, s);
    const topo::SceneTopology& t = gpu->topology;

    gpu->vpls = vk::Buffer(ctx.vk, VkDeviceSize(s.vpls) * sizeof(GpuVpl),
                           VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT |
                               VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                           vk::MemoryUsage::DeviceLocal, ctx.tag("vpls"));
    ctx.vk.submitAndWait([&](VkCommandBuffer cmd) {
        vkCmdFillBuffer(cmd, gpu->vpls.handle(), 0, VK_WHOLE_SIZE, 0);
    });
    gpu->rsm = std::make_unique<ReflectiveShadowMap>(
        ctx.vk, ctx.gpuScene, ctx.shared.shadows().lightBuffer(), s.rsmResolution, ctx.tag("gi"));
    gpu->pixels =
        std::make_unique<topo::PixelClusters>(ctx.vk, ctx.shared.gbuffer(), t, ctx.tag("gi"));
    const uint64_t capacity = uint64_t(s.listCapacityMiB) * 1024 * 1024 / 8;
    gpu->lighting =
        std::make_unique<topo::GateLighting>(ctx.vk, ctx.shared.gbuffer(), *gpu->pixels, gpu->vpls,
                                             s.vpls, gateTable(t, s), capacity, ctx.tag("gi"));
    m_gpu = std::move(gpu);
    applySettings(ctx);
    if (s.useCache) {
        // The debug glTF (skeleton, kept nodes, gate disks at this run's radius rule) next to
        // the cache entry, for any glTF viewer.
        std::vector<float> radii;
        for (const topo::WorldGate& g : t.gates)
            radii.push_back(gateRadius(g, s));
        const auto gltf = topo::defaultTopologyCacheDir() /
                          (topo::topologyKey(ctx.scene, topologySettings(s)) + ".gltf");
        topo::exportTopologyGltf(t, gltf.string(), radii);
        ctx.note("topology debug glTF (skeleton, nodes, gates by cluster): " + gltf.string());
    }

    const Light& l = ctx.scene.lights[size_t(light)];
    ctx.note("main light " + std::to_string(light) + " ('" + l.name + "', " +
             (l.type == LightType::Spot ? "spot" : "directional") + "): RSM " +
             std::to_string(s.rsmResolution) + "^2, " + std::to_string(s.vpls) + " VPLs");
    ctx.note("topology " + std::to_string(s.voxelResolution) +
             "^3: " + std::to_string(t.skeletonVoxels) + " skeleton voxels, " +
             std::to_string(t.segmentation.kept.size()) + " kept nodes, " +
             std::to_string(t.segmentation.clusterCount) + " visibility clusters, " +
             std::to_string(t.gates.size()) + " gates");
    if (ctx.scene.lights.size() > 1)
        ctx.skip("bounce from other lights",
                 "VPLs come from one main light; the others are direct only");
    if (ctx.scene.caps.emissiveTriangleCount > 0)
        ctx.skip("bounce from emissive surfaces", "not a light of the method");
    if (s.visibility == TopoVisibility::Unshadowed)
        ctx.skip("visibility", "visibility = none: every VPL unshadowed (Table II baseline)");
    if (s.visibility == TopoVisibility::SameClusterOnly || t.gates.empty())
        ctx.skip("gate lighting", t.gates.empty() ? "the topology has no gates (one cluster)"
                                                  : "visibility = same_cluster");
    // A node holding much of the skeleton is empty space that did not thin (issue 30: open sky
    // collapsed into one clump before the bounds closed the empty space).
    uint32_t node = 0;
    const float largest = topo::largestNodeSkeletonPercent(t.graph, &node);
    ctx.stat("largest_node_skeleton_percent", largest);
    // A tiny skeleton (closed rooms thin to a voxel each) is not a clump: ask for many voxels.
    const double voxels = double(largest) / 100.0 * double(t.graph.voxelNode.size());
    if (largest > 1.0f && voxels > 64.0) {
        const std::string text =
            "warning: skeleton node " + std::to_string(node) + " holds " +
            std::to_string(int64_t(voxels)) + " voxels, " + std::to_string(largest) +
            " % of the skeleton (> 1 %): a clump of empty space that did not thin (a solid "
            "standing free in the empty space?), whose cluster will take many VPLs";
        ctx.note(text);
        std::fprintf(stderr, "gilab: topovpl: %s\n", text.c_str());
    }
    if (t.anchoredVoxels > 0)
        ctx.note("lifespan filter: " + std::to_string(t.anchoredVoxels) +
                 " skeleton voxels anchored by lifespan > opening - distance");
    ctx.stat("visibility_clusters", t.segmentation.clusterCount);
    ctx.stat("gates", double(t.gates.size()));
    ctx.stat("skeleton_voxels", t.skeletonVoxels);
    ctx.stat("kept_nodes", double(t.segmentation.kept.size()));
    ctx.stat("la_capacity_entries", double(m_gpu->lighting->entryCapacity()));
    ctx.stat("memory_mib", double(m_gpu->lighting->bytes() + m_gpu->vpls.size() +
                                  uint64_t(t.voxelCluster.size()) * 4) /
                               (1024.0 * 1024.0));
}

void TopovplTechnique::applySettings(const TechniqueContext& ctx) {
    m_settings = topovplSettingsFrom(ctx.params);
    m_gpu->lighting->updateGates(gateTable(m_gpu->topology, m_settings).gates);
}

void TopovplTechnique::onParamsChanged(TechniqueContext& ctx,
                                       const std::vector<std::string>& keys) {
    if (!m_gpu || ctx.params.changesNeedRebuild(keys)) {
        setup(ctx);
        return;
    }
    applySettings(ctx);
}

UpdateKind TopovplTechnique::update(TechniqueContext& ctx, const SceneChanges& changes) {
    if (changes.geometry)
        throw Error(
            "topovpl: moving geometry is unsupported: the topology of the empty space is "
            "precomputed for static geometry (Noel & Biri 2014 §III)");
    if (!m_gpu) return Technique::update(ctx, changes);
    // VPLs, clusters and lists are rebuilt every frame from the updated light and camera.
    return UpdateKind::None;
}

void TopovplTechnique::render(TechniqueContext& ctx, VkCommandBuffer cmd, FrameTargets& targets) {
    if (!m_gpu) throw Error("topovpl: render() before setup()");
    TopovplGpu& g = *m_gpu;
    const TopovplSettings& s = m_settings;
    const Camera& cam = ctx.scene.camera;
    {
        PassScope pass(ctx, cmd, "gp.clusters");
        g.pixels->record(cmd, cam.position);
    }
    {
        PassScope pass(ctx, cmd, "misc.rsm");
        g.rsm->record(cmd, ctx.shared.shadows().lights()[g.light], g.light);
    }
    {
        PassScope pass(ctx, cmd, "misc.vpl_sample");
        g.rsm->recordVpls(cmd, g.vpls, 0, s.vpls, vpl::cranleyPattersonShift(s.seed));
    }
    {
        PassScope pass(ctx, cmd, "misc.vpl_clusters");
        g.lighting->recordVplClusters(cmd);
    }
    {
        // Exponential slices from the nearest to the farthest point of the scene's box.
        const Bounds& b = ctx.scene.caps.bounds;
        float zFar = 0.0f;
        for (int i = 0; i < 8; ++i) {
            const glm::vec3 c((i & 1) ? b.hi.x : b.lo.x, (i & 2) ? b.hi.y : b.lo.y,
                              (i & 4) ? b.hi.z : b.lo.z);
            zFar = std::max(zFar, glm::dot(c - cam.position, cam.forward()));
        }
        const float zNear = std::max(cam.nearZ, 1e-4f * g.diagonal);
        PassScope pass(ctx, cmd, "iugc");
        g.lighting->recordIugc(cmd, cam.position, cam.forward(), zNear, std::max(zFar, zNear),
                               s.tileSize, s.depthSlices);
    }
    {
        PassScope pass(ctx, cmd, "la");
        const topo::LaMode mode = s.visibility == TopoVisibility::Gates ? topo::LaMode::Gates
                                  : s.visibility == TopoVisibility::SameClusterOnly
                                      ? topo::LaMode::SameCluster
                                      : topo::LaMode::Unshadowed;
        g.lighting->recordLa(cmd, mode, s.farClusterOnly);
    }
    {
        PassScope pass(ctx, cmd, "il");
        g.lighting->recordIl(cmd, targets.indirect, s.clampDistance * g.diagonal);
    }
    if (s.sameClusterStat) {
        // Not part of the method: a diagnostic, left out of the frame's GPU time (docs/timing.md).
        PassScope pass(ctx, cmd, "diag.same_cluster_share");
        g.lighting->recordSameClusterShare(cmd, s.clampDistance * g.diagonal);
    }
}

void TopovplTechnique::frameFinished(TechniqueContext& ctx) {
    if (!m_gpu) return;
    const topo::GateLightingStats st = m_gpu->lighting->readStats();
    const double total = st.keptIrradiance + st.removedIrradiance;
    ctx.stat("clamped_energy_percent", total > 0.0 ? 100.0 * st.removedIrradiance / total : 0.0);
    ctx.stat("geometry_clusters", st.geometryClusters);
    ctx.stat("la_entries", double(st.entries));
    ctx.stat("la_overflow_entries", double(st.overflow));
    ctx.stat("valid_vpls", st.validVpls);
    ctx.stat("vpls_without_cluster", st.vplsWithoutCluster);
    if (m_settings.sameClusterStat) {
        const double all = st.unshadowedRadiance;
        ctx.stat("same_cluster_unshadowed_percent",
                 all > 0.0 ? 100.0 * st.sameClusterRadiance / all : 0.0);
    }
    if (st.overflow > 0)
        ctx.note("light assignment overflow: " + std::to_string(st.overflow) + " of " +
                 std::to_string(st.entries) +
                 " entries did not fit list_capacity_mib; those lights are missing");
}

std::vector<DebugView> TopovplTechnique::debugViews() {
    if (!m_gpu) return {};
    return {{"visibility_clusters", &m_gpu->pixels->debugView()}};
}

bool TopovplTechnique::readVplSet(VplSet& out) {
    if (!m_gpu) return false;
    out.vpls = m_gpu->vpls.downloadVector<GpuVpl>(m_settings.vpls);
    out.clampDistance = m_settings.clampDistance * m_gpu->diagonal;
    out.bounceScale = glm::vec2(1.0f);
    return true;
}

GILAB_REGISTER_TECHNIQUE(TopovplTechnique)

}  // namespace gilab
