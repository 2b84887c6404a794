#pragma once
/**
 * `dvs`: deferred voxel shading, J. Villegas, "Deferred Voxel Shading for Real-Time Global
 * Illumination" (CLEI 2016; the VCTRenderer write-up). Extraction: notes 003;
 * techniques/dvs/README.md.
 *
 * Set-up (ctx.submitTimed):
 *   voxelize, voxel_resolve  shared Voxelizer (albedo, normal, emission volumes)
 *   voxel_direct   L1: every voxel lit by every pass light, normal-weighted Lambert (E1-E3,
 *                  with 1/pi), shadow maps or voxel ray casting (E4)  -> VoxelRadiance::base()
 *   filter         F: six directional (N/2)^3 volumes with mips (E5)
 *   voxel_bounce   G1 (bounces = 2): per-voxel diffuse cones, base = direct + first bounce
 *   filter2        F again
 * Update (issue 11): as the source, L1, F (and G1, F with bounces = 2) run again whenever a
 * light changes (same pass names, timed as the frame's update), reading the shadow maps the
 * harness re-rendered just before; the voxelization (static geometry) is kept. A camera change
 * redoes nothing (P1 reads the G-buffer every frame).
 * Per frame: "trace" (P1) over the shared G-buffer: diffuse cones (E14), specular cone,
 * AO (debug view "ao"), optional cone shadows for the direct layer (E13).
 *
 * Deviations (techniques/dvs/README.md): HDR RGBA16F radiance, physically consistent 1/pi and no GI
 * strength, our light falloff (lights.glsl), voxel centres, emitters lit through the shared emitter
 * samples (their direct light on the voxels) and never gathered as raw emission.
 * Parameters: techniques/dvs/dvs_settings.cpp.
 */
#include <memory>

#include "core/technique/technique.h"
#include "dvs_settings.h"

namespace gilab {

class Voxelizer;
class VoxelRadiance;
class DvsVoxelLighting;
class DvsPixelTrace;

class DvsTechnique final : public Technique {
public:
    DvsTechnique();
    ~DvsTechnique() override;
    static TechniqueInfo describe();
    void setup(TechniqueContext& ctx) override;
    UpdateKind update(TechniqueContext& ctx, const SceneChanges& changes) override;
    void render(TechniqueContext& ctx, VkCommandBuffer cmd, FrameTargets& targets) override;
    std::vector<DebugView> debugViews() override;

private:
    /** L1, F (G1, F with bounces >= 2) for the current lights and shadow maps. */
    void recordVoxelLighting(TechniqueContext& ctx, VkCommandBuffer cmd, int bounces);

    std::unique_ptr<Voxelizer> m_voxelizer;
    std::unique_ptr<VoxelRadiance> m_radiance;
    std::unique_ptr<DvsVoxelLighting> m_lighting;
    std::unique_ptr<DvsPixelTrace> m_trace;
    bool m_specularSkipNoted = false;
};

}  // namespace gilab
