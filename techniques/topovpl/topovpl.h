#pragma once
/**
 * `topovpl`: real-time global illumination with topological information, S. Noël and V. Biri,
 * GSTF Journal on Computing 4(1), 2014. Extraction: notes 004; techniques/topovpl/README.md.
 * One diffuse bounce of one main light (spot or directional) through VPLs whose visibility is
 * the precomputed topology of the empty space instead of shadow maps: a VPL lights a pixel of
 * its own visibility cluster, or one seen through a gate of its cluster (E6).
 *
 * Set-up (once per scene geometry and set-up parameters, cached on disk, timed step by step):
 * voxelization, distance transform, thinning, segmentation, clustering, nearest node
 * (scene_topology.h, topology_cache.h).
 *
 * Per frame, timed under the paper's Table I names (GP = the shared pass "gbuffer" + gp.clusters):
 *   gp.clusters          the visibility cluster of every G-buffer pixel (pixel_clusters.h)
 *   misc.rsm             reflective shadow map of the main light (core/vpl/rsm.h)
 *   misc.vpl_sample      N VPLs from it; misc.vpl_clusters: their visibility clusters
 *   iugc                 unique geometry clusters (tiles x slices x visibility cluster)
 *   la                   light assignment with the sphere-cone test (E8)
 *   il                   indirect lighting with the exact gate test (E7) and the near-VPL clamp
 * Static geometry only (the topology is precomputed, §III): moving geometry is refused.
 */
#include <memory>

#include "core/technique/technique.h"
#include "topovpl_settings.h"

namespace gilab {

struct TopovplGpu;

class TopovplTechnique final : public Technique {
public:
    TopovplTechnique();
    ~TopovplTechnique() override;
    static TechniqueInfo describe();
    SupportResult checkSupport(const Scene& scene, const ParamSet& params) const override;
    void setup(TechniqueContext& ctx) override;
    void onParamsChanged(TechniqueContext& ctx, const std::vector<std::string>& keys) override;
    UpdateKind update(TechniqueContext& ctx, const SceneChanges& changes) override;
    void render(TechniqueContext& ctx, VkCommandBuffer cmd, FrameTargets& targets) override;
    void frameFinished(TechniqueContext& ctx) override;
    std::vector<DebugView> debugViews() override;
    bool readVplSet(VplSet& out) override;

private:
    void applySettings(const TechniqueContext& ctx);

    TopovplSettings m_settings;
    std::unique_ptr<TopovplGpu> m_gpu;
};

}  // namespace gilab
