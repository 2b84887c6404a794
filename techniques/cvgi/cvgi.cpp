#include "cvgi.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "core/passes/shared_passes.h"
#include "core/scene/animation.h"
#include "core/scene/scene.h"
#include "core/technique/registry.h"
#include "core/util/error.h"
#include "core/vk/context.h"
#include "core/voxel/voxel_compaction.h"
#include "core/voxel/voxelizer.h"
#include "cvgi_gpu.h"
#include "cvgi_readback.h"
#include "cvgi_setup.h"

namespace gilab {
namespace {

constexpr float kCubeSpotOuterRad = 1.4835299f;  // spots wider than 85 deg have no 2D map

std::string mib(double bytes) {
    char s[32];
    std::snprintf(s, sizeof(s), "%.1f MiB", bytes / (1024.0 * 1024.0));
    return s;
}

}  // namespace

CvgiTechnique::CvgiTechnique() = default;
CvgiTechnique::~CvgiTechnique() = default;

TechniqueInfo CvgiTechnique::describe() {
    TechniqueInfo info;
    info.id = "cvgi";
    info.description =
        "Clustered voxel GI: voxel clusters, per-face cached cluster visibility, per-face "
        "irradiance gathered on emitter changes (one diffuse bounce)";
    info.citation =
        "A. Cosin Ayerbe, G. Patow, \"Clustered voxel real-time global illumination\", "
        "Computers & Graphics 103 (2022), doi 10.1016/j.cag.2022.01.005";
    info.params = cvgiParamSpecs();
    info.indirectBounces = 1;
    info.checkParams = [](const ParamSet& p) { (void)cvgiSettingsFrom(p); };
    info.supports.pointLights = false;       // would need six distance maps (§5.2)
    info.supports.emissiveSurfaces = false;  // only emitters with a shadow-map camera
    return info;
}

SupportResult CvgiTechnique::checkSupport(const Scene& scene, const ParamSet& params) const {
    SupportResult base = Technique::checkSupport(scene, params);
    if (!base.supported) {
        base.reason +=
            " (the paper's emitters need one distance map from a camera: spot or "
            "directional lights)";
        return base;
    }
    bool emitter = false;
    for (const Light& l : scene.lights) {
        if (l.type == LightType::Spot && l.outerConeRad > kCubeSpotOuterRad)
            return {false, "spot light '" + l.name +
                               "' is wider than 85 deg: it has no single distance map"};
        emitter = emitter || l.type == LightType::Spot || l.type == LightType::Directional;
    }
    if (!emitter) return {false, "needs a spot or directional light (the paper's emitters)"};
    return {};
}

void CvgiTechnique::setup(TechniqueContext& ctx) {
    m_gpu.reset();
    const CvgiSettings s = cvgiSettingsFrom(ctx.params);
    const VoxelGrid grid(ctx.scene.caps.bounds, s.voxelResolution);
    const uint32_t n = s.voxelResolution;

    // §4.1: voxelization with fragment lists, then the prefix-sum compaction.
    VoxelizerOptions vo;
    const uint64_t maxFragments =
        ctx.vk.properties().limits.maxStorageBufferRange / sizeof(GpuVoxelFragment);
    vo.fragmentCapacity =
        uint32_t(std::min<uint64_t>(maxFragments, std::max(1u << 20, 24 * n * n)));
    auto voxelizer = std::make_unique<Voxelizer>(ctx.vk, ctx.gpuScene, grid, vo);
    VoxelFragmentLists& lists = *voxelizer->fragments();
    auto voxelize = [&] {
        ctx.submitTimed([&](VkCommandBuffer cmd) {
            PassScope pass(ctx, cmd, "voxelization");
            voxelizer->record(cmd, nullptr);
        });
    };
    voxelize();
    const uint32_t firstCapacity = lists.capacity();
    if (voxelizer->growFragmentsIfOverflowed()) {
        ctx.note("fragment buffer grown from " + std::to_string(firstCapacity) + " to " +
                 std::to_string(lists.capacity()) + " fragments: voxelization ran twice");
        voxelize();
    }
    const uint32_t fragmentCount = lists.written();
    VoxelCompaction compaction(ctx.vk, grid, lists.heads());
    ctx.submitTimed([&](VkCommandBuffer cmd) {
        PassScope pass(ctx, cmd, "prefix_sum");
        compaction.recordScan(cmd);
    });
    const uint32_t occupied = compaction.readOccupied();
    ctx.submitTimed([&](VkCommandBuffer cmd) {
        PassScope pass(ctx, cmd, "prefix_sum");
        compaction.recordFill(cmd, occupied);
    });
    cvgi::CompactVoxels voxels;
    ctx.timeCpu("voxel_readback",
                [&] { voxels = readCompactVoxels(grid, compaction, lists, fragmentCount); });
    voxelizer.reset();  // the fragments and heads are no longer needed

    // §4.2-4.3 on the CPU (techniques/cvgi/README.md "Where it runs").
    std::vector<uint8_t> axis;
    cvgi::Clusters clusters;
    cvgi::FaceVisibility visibility;
    ctx.timeCpu("heuristic_normal", [&] { axis = cvgi::heuristicNormals(voxels); });
    ctx.timeCpu("clustering", [&] {
        cvgi::ClusteringParams cp;
        cp.initialClusters =
            s.initialClusters > 0 ? s.initialClusters : cvgi::paperInitialClusters(n);
        cp.iterations = s.clusterIterations;
        cp.angleDeg = s.clusterAngleDeg;
        clusters = cvgi::clusterVoxels(voxels, axis, cp);
    });
    ctx.timeCpu("cluster_visibility", [&] {
        cvgi::VisibilityParams vp;
        vp.raysPerFace = s.raysPerFace;
        vp.rotation = cvgi::seedRotation(s.seed);
        visibility = cvgi::faceVisibility(voxels, clusters, vp);
    });

    m_gpu = std::make_unique<CvgiGpu>(ctx.vk, ctx.gpuScene, ctx.shared, grid,
                                      std::move(compaction.voxelIndex()),
                                      std::move(compaction.hashedPosition()), voxels, axis,
                                      clusters, visibility, s, ctx.tag("gi"));
    const uint32_t v = voxels.count();
    ctx.stat("voxels", v);
    ctx.stat("fragments", fragmentCount);
    ctx.stat("seeds", clusters.seeds);
    ctx.stat("clusters", clusters.count());
    ctx.stat("cluster_percent", v > 0 ? 100.0 * clusters.count() / v : 0.0);
    ctx.stat("unassigned_voxels", clusters.unassigned);
    ctx.stat("visibility_entries", double(visibility.clusters.size()));
    ctx.stat("visibility_max_per_face", visibility.maxPerFace);
    // §4.3's "14-22%" is over the brute-force layout of V * N * 6 entries (one per voxel, face
    // and grid step); the share of one entry per ray (V * 6 * rays) is kept beside it.
    const double entries = double(visibility.clusters.size());
    ctx.stat("visibility_compacted_percent",
             visibility.paperEntries > 0 ? 100.0 * entries / double(visibility.paperEntries) : 0.0);
    ctx.stat("visibility_per_ray_percent",
             visibility.uncompactedEntries > 0
                 ? 100.0 * entries / double(visibility.uncompactedEntries)
                 : 0.0);
    m_sightings = cvgi::clusterSightings(visibility, clusters.count());
    // Mean plane area in each voxel (v0^2 / |n|_1 of its mean normal; v0^2 when the normals
    // cancel): the lit voxels' power, Sum B A, for the stat lit_power_w (issue 43).
    m_voxelArea.assign(v, 0.0f);
    const float v0 = grid.voxelSize();
    for (uint32_t i = 0; i < v; ++i) {
        const glm::vec3 m = voxels.meanNormal[i];
        const float len = glm::length(m);
        const float l1 = len > 0.1f ? (std::abs(m.x) + std::abs(m.y) + std::abs(m.z)) / len : 1.0f;
        m_voxelArea[i] = v0 * v0 / l1;
    }
    ctx.stat("clusters_per_face", m_sightings.clustersPerFace());
    ctx.stat("memory_final_mib", double(m_gpu->finalBytes()) / (1024.0 * 1024.0));
    ctx.note("voxel grid " + std::to_string(n) + "^3: " + std::to_string(v) + " voxels, " +
             std::to_string(clusters.count()) + " clusters from " + std::to_string(clusters.seeds) +
             " seeds, " + std::to_string(clusters.unassigned) +
             " voxels unassigned (never a source, still occluders); visibility " +
             std::to_string(visibility.clusters.size()) + " entries (" +
             mib(double(m_gpu->visibilityBytes())) + " with the offsets); bounce + frame buffers " +
             mib(double(m_gpu->finalBytes())));
    ctx.note(std::to_string(m_gpu->emitterCount()) +
             " emitter(s) with a distance map; static geometry assumed (a geometry change "
             "re-runs the set-up)");
    if (m_gpu->cameraMapClamped())
        ctx.note("camera distance map clamped to the device's image limit: " +
                 std::to_string(m_gpu->cameraMapWidth()) + "x" +
                 std::to_string(m_gpu->cameraMapHeight()) + " (camera_map_size " +
                 std::to_string(s.cameraMapSize) + " at this aspect is larger)");
    if (ctx.scene.lights.size() > m_gpu->emitterCount())
        ctx.skip("bounce from other lights", "only spot and directional lights are emitters");
    emitterUpdate(ctx);
}

void CvgiTechnique::emitterUpdate(TechniqueContext& ctx) {
    const float aspect = float(ctx.width) / float(std::max(ctx.height, 1u));
    m_gpu->setCamera(ctx.scene.camera, aspect);
    ctx.submitTimed([&](VkCommandBuffer cmd) { m_gpu->recordEmitterUpdate(ctx, cmd); });
    m_statsDue = true;  // read back in frameFinished(), outside the timed update
}

void CvgiTechnique::frameFinished(TechniqueContext& ctx) {
    if (!m_statsDue || !m_gpu) return;
    m_statsDue = false;
    recordUpdateStats(ctx);
}

void CvgiTechnique::recordUpdateStats(TechniqueContext& ctx) {
    const CvgiCounters c = m_gpu->readCounters();
    ctx.stat("lit_voxels", c.litVoxels);
    ctx.stat("visible_voxels", c.visible);
    ctx.stat("gathered_voxels", c.gathered);
    // §4.3's sampling (ours): how many lit clusters no open face's rays meet (the paper's gather
    // never adds them), the share of the open faces' rays that stop in a lit cluster, the lit
    // clusters in an open face's list and the rays that found each (1 = at the sampling limit).
    const std::vector<uint32_t> lit = m_gpu->readLitCounts();
    uint64_t litClusters = 0, neverHit = 0, raysOnLit = 0, litEntries = 0;
    for (size_t k = 0; k < lit.size() && k < m_sightings.rayHits.size(); ++k) {
        if (lit[k] == 0) continue;
        ++litClusters;
        if (m_sightings.rayHits[k] == 0) ++neverHit;
        raysOnLit += m_sightings.rayHits[k];
        litEntries += m_sightings.faceHits[k];
    }
    const double openRays = double(m_sightings.openFaces) * double(m_sightings.rays);
    ctx.stat("lit_clusters", double(litClusters));
    ctx.stat("lit_clusters_never_hit_percent",
             litClusters ? 100.0 * double(neverHit) / double(litClusters) : 0.0);
    ctx.stat("rays_seeing_lit_percent", openRays > 0 ? 100.0 * double(raysOnLit) / openRays : 0.0);
    ctx.stat("lit_clusters_per_face",
             m_sightings.openFaces ? double(litEntries) / double(m_sightings.openFaces) : 0.0);
    ctx.stat("rays_per_lit_entry", litEntries ? double(raysOnLit) / double(litEntries) : 0.0);
    // The power the lit voxels hold, Sum B A (mean of rgb, W): against the path tracer's
    // one-bounce emission (vct's power_photons_reflected_w on the same scene), per resolution.
    const std::vector<glm::vec4> light = m_gpu->readVoxelLight();
    double power = 0.0;
    for (size_t i = 0; i < light.size() && i < m_voxelArea.size(); ++i)
        power += double(light[i].r + light[i].g + light[i].b) / 3.0 * double(m_voxelArea[i]);
    ctx.stat("lit_power_w", power);
}

void CvgiTechnique::onParamsChanged(TechniqueContext& ctx, const std::vector<std::string>& keys) {
    if (!m_gpu || ctx.params.changesNeedRebuild(keys)) {
        setup(ctx);
        return;
    }
    m_gpu->setSettings(cvgiSettingsFrom(ctx.params));
    emitterUpdate(ctx);  // the cached faces depend on every update parameter
}

UpdateKind CvgiTechnique::update(TechniqueContext& ctx, const SceneChanges& changes) {
    if (changes.geometry || !m_gpu) return Technique::update(ctx, changes);
    if (!changes.lights.empty()) {
        emitterUpdate(ctx);  // §4.4: an emitter change invalidates every cached face
        return UpdateKind::Incremental;
    }
    if (!changes.camera) return UpdateKind::None;
    const float aspect = float(ctx.width) / float(std::max(ctx.height, 1u));
    m_gpu->setCamera(ctx.scene.camera, aspect);
    ctx.submitTimed([&](VkCommandBuffer cmd) { m_gpu->recordCameraUpdate(ctx, cmd); });
    m_statsDue = true;
    return UpdateKind::Incremental;
}

void CvgiTechnique::render(TechniqueContext& ctx, VkCommandBuffer cmd, FrameTargets& targets) {
    if (!m_gpu) throw Error("cvgi: render() before setup()");
    PassScope pass(ctx, cmd, "final_frame");
    m_gpu->recordFinalFrame(cmd, targets.indirect);
}

GILAB_REGISTER_TECHNIQUE(CvgiTechnique)

}  // namespace gilab
