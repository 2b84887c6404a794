#pragma once
/**
 * `cvgi`: clustered voxel real-time global illumination, A. Cosin Ayerbe and G. Patow, Computers &
 * Graphics 103 (2022), doi 10.1016/j.cag.2022.01.005. Extraction: notes 000;
 * techniques/cvgi/README.md. One indirect diffuse bounce, static geometry, spot and directional
 * emitters (each needs one distance map; point lights and emissive surfaces are not supported).
 *
 * Set-up (Table 1; GPU passes by submitTimed, CPU passes by timeCpu):
 *   voxelization        shared Voxelizer with per-voxel fragment lists (§4.1)          GPU
 *   prefix_sum          VoxelCompaction of the voxel buffer (§4.1, Fig. 4)             GPU
 *   voxel_readback      compacted voxels and fragments to the host                     CPU
 *   heuristic_normal    axis normal from free-neighbour counts (§4.2, Fig. 7)          CPU
 *   clustering          Algorithm 1, empty clusters compacted, cluster info            CPU
 *   cluster_visibility  per-face 3D Bresenham rays, de-duplicated, compacted (§4.3)   CPU
 *   then a first emitter update (below).
 * Emitter update (Table 2; update() on a light change, also on parameter changes):
 *   dist_shadow_map, lit_cluster, camera_visible_voxel, light_bounce, gaussian_filtering.
 * Camera-only change: camera_visible_voxel, light_bounce (newly visible voxels only),
 *   gaussian_filtering.
 * Per frame: final_frame (face choice, bilinear face interpolation, albedo / pi).
 */
#include <memory>
#include <vector>

#include "core/technique/technique.h"
#include "cvgi_settings.h"
#include "cvgi_setup.h"

namespace gilab {

class CvgiGpu;

class CvgiTechnique final : public Technique {
public:
    CvgiTechnique();
    ~CvgiTechnique() override;
    static TechniqueInfo describe();
    SupportResult checkSupport(const Scene& scene, const ParamSet& params) const override;
    void setup(TechniqueContext& ctx) override;
    void onParamsChanged(TechniqueContext& ctx, const std::vector<std::string>& keys) override;
    UpdateKind update(TechniqueContext& ctx, const SceneChanges& changes) override;
    void render(TechniqueContext& ctx, VkCommandBuffer cmd, FrameTargets& targets) override;
    /** Reads the update's counters back (stats), after the frame: not part of the timed update. */
    void frameFinished(TechniqueContext& ctx) override;

private:
    void emitterUpdate(TechniqueContext& ctx);
    void recordUpdateStats(TechniqueContext& ctx);

    std::unique_ptr<CvgiGpu> m_gpu;
    bool m_statsDue = false;             // an update ran whose counters are not read yet
    cvgi::ClusterSightings m_sightings;  // what the faces' rays see, for the update stats
    std::vector<float> m_voxelArea;      // per voxel, the mean plane area inside it (m^2)
};

}  // namespace gilab
