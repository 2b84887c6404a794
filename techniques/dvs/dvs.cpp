#include "dvs.h"

#include <cstdio>
#include <string>

#include "core/passes/shared_passes.h"
#include "core/scene/animation.h"
#include "core/scene/scene.h"
#include "core/technique/registry.h"
#include "core/util/error.h"
#include "core/voxel/voxel_radiance.h"
#include "core/voxel/voxelizer.h"
#include "pixel_trace.h"
#include "voxel_lighting.h"

namespace gilab {

DvsTechnique::DvsTechnique() = default;
DvsTechnique::~DvsTechnique() = default;

TechniqueInfo DvsTechnique::describe() {
    TechniqueInfo info;
    info.id = "dvs";
    info.description =
        "Deferred voxel shading: per-voxel direct light + anisotropic mips, per-pixel cone "
        "tracing (optional per-voxel second bounce)";
    info.citation =
        "J. Villegas, \"Deferred Voxel Shading for Real-Time Global Illumination\", CLEI 2016 "
        "(IEEE 7833375); VCTRenderer write-up";
    info.params = dvsParamSpecs();
    info.indirectBounces = 1;
    info.bouncesParam = "bounces";
    info.checkParams = [](const ParamSet& p) { (void)dvsSettingsFrom(p); };
    // Emitters light the voxels through the shared emitter samples (direct light at the voxel,
    // the source of the first bounce); their raw emission is never gathered
    // (techniques/dvs/README.md).
    info.supports.emissiveSurfaces = true;
    return info;
}

void DvsTechnique::setup(TechniqueContext& ctx) {
    const DvsSettings s = dvsSettingsFrom(ctx.params);
    m_trace.reset();
    m_lighting.reset();
    m_radiance.reset();
    m_voxelizer.reset();

    const VoxelGrid grid(ctx.scene.caps.bounds, s.voxelResolution);
    m_voxelizer = std::make_unique<Voxelizer>(ctx.vk, ctx.gpuScene, grid);
    m_radiance =
        std::make_unique<VoxelRadiance>(ctx.vk, grid, VoxelRadianceOptions{}, ctx.tag("radiance"));
    m_radiance->setSurfaceNormals(m_voxelizer->volumes().normal);  // voxels face their side
    m_lighting = std::make_unique<DvsVoxelLighting>(ctx.vk, *m_voxelizer, *m_radiance,
                                                    ctx.shared.shadows(), s, ctx.tag("lighting"));
    ctx.submitTimed([&](VkCommandBuffer cmd) {
        m_voxelizer->record(cmd, ctx.timer);
        recordVoxelLighting(ctx, cmd, s.bounces);
    });
    // The G1 scratch volume stays: a light change re-runs G1 (issue 11)
    m_voxelizer->releaseAccumulators();
    m_trace = std::make_unique<DvsPixelTrace>(ctx.vk, ctx.shared, *m_radiance, ctx.tag("trace"));

    const double n3 = double(s.voxelResolution) * s.voxelResolution * s.voxelResolution;
    char kept[64];
    std::snprintf(kept, sizeof(kept), "%.2f MiB",
                  n3 * (s.bounces >= 2 ? 8.0 : 0.0) / (1024.0 * 1024.0));
    ctx.note("voxel grid " + std::to_string(s.voxelResolution) + "^3, voxel " +
             std::to_string(grid.voxelSize()) +
             " m; voxel lighting computed at set-up and re-run (L1, F" +
             std::string(s.bounces >= 2 ? ", G1, F" : "") +
             ") when a light changes; kept for that: the voxelizer's volumes" +
             std::string(s.bounces >= 2 ? " and the G1 scratch volume (" + std::string(kept) + ")"
                                        : ""));
    if (ctx.scene.caps.hasEmissive)
        ctx.note("emitters light the voxels through the shared emitter samples (L1)");
    if (s.pixelShadows == DvsPixelShadows::Cone)
        ctx.note("direct layer recomputed with cone shadows (pixel_shadows = cone)");
    if (s.combine == DvsCombine::Source)
        ctx.note("combine = source: direct and indirect multiplied by AO (not physically based)");
    if (!ctx.scene.caps.hasGlossy)
        ctx.skip("specular", "scene has no glossy materials");
    else if (!s.specular)
        ctx.skip("specular", "specular = false");
}

void DvsTechnique::recordVoxelLighting(TechniqueContext& ctx, VkCommandBuffer cmd, int bounces) {
    {
        PassScope pass(ctx, cmd, "voxel_direct");
        m_lighting->recordDirect(cmd);  // writes every voxel of the base (0 where empty)
    }
    {
        PassScope pass(ctx, cmd, "filter");
        m_radiance->filter(cmd);
    }
    if (bounces >= 2) {
        {
            PassScope pass(ctx, cmd, "voxel_bounce");
            m_lighting->recordBounce(cmd);
        }
        PassScope pass(ctx, cmd, "filter2");
        m_radiance->filter(cmd);
    }
}

UpdateKind DvsTechnique::update(TechniqueContext& ctx, const SceneChanges& changes) {
    if (changes.geometry || !m_lighting) return Technique::update(ctx, changes);
    if (changes.lights.empty()) return UpdateKind::None;  // camera only: P1 reads the G-buffer
    // The harness has re-uploaded the pass light table and re-rendered the moved lights' shadow
    // maps (a finished submission) before calling update(): L1 reads the new ones
    const DvsSettings s = dvsSettingsFrom(ctx.params);
    ctx.submitTimed([&](VkCommandBuffer cmd) { recordVoxelLighting(ctx, cmd, s.bounces); });
    return UpdateKind::Incremental;
}

void DvsTechnique::render(TechniqueContext& ctx, VkCommandBuffer cmd, FrameTargets& targets) {
    if (!m_trace) throw Error("dvs: render() before setup()");
    const DvsSettings s = dvsSettingsFrom(ctx.params);
    DvsSettings frame = s;
    frame.specular = s.specular && ctx.scene.caps.hasGlossy;
    PassScope pass(ctx, cmd, "trace");
    m_trace->record(cmd, frame, ctx.scene.camera, targets.indirect, targets.direct);
}

std::vector<DebugView> DvsTechnique::debugViews() {
    if (!m_trace) return {};
    return {{"ao", &m_trace->aoImage()}};
}

GILAB_REGISTER_TECHNIQUE(DvsTechnique)

}  // namespace gilab
