#pragma once
/**
 * `ssvp`: screen-space VPL propagation with clustered paraboloid maps, V. M. Aranha, M. C. F.
 * Macedo, A. L. Apolinario Jr. Extraction: notes 002; techniques/ssvp/README.md. Up to two diffuse
 * bounces of one main light (spot or directional), everything redone every frame, so a moving
 * light or camera costs nothing beyond a static frame.
 *
 * Per frame, timed under the paper's Table I stages (G-buffer is the shared pass "gbuffer"):
 *   misc.rsm            reflective shadow map of the main light (core/vpl/rsm.h)
 *   misc.vpl_sample     N1 first-bounce VPLs at the Hammersley points (Eq. 1)
 *   misc.kmeans         K-means over them, Eq. 2 (corrected), warm start, <= 5 iterations
 *   paraboloid.maps     one layered paraboloid map per cluster (core/vpl/paraboloid_maps.h)
 *   misc.map_members    does each cluster's map see its members (map_members = reassign moves
 *                       the unseen ones; ours)
 *   misc.second_bounce  N2 / C second-bounce VPLs per cluster on its map's unit disk
 *   with second_bounce_visibility = own_maps (ours, not in the paper):
 *     misc.second_kmeans        K-means over the second-bounce VPLs into C2 clusters
 *     paraboloid.second_bounce  their C2 maps (layers C .. C + C2 of the same array)
 *     misc.second_map_members   the member test for those clusters
 *   shade.gather        interleaved I x I gathering, Eq. 6 in watts, clustered visibility for
 *                       the first bounce (both with own_maps), near-VPL clamp
 * (core/vpl/vpl_shading.h) shade.blur          edge-aware Gaussian of the irradiance, then albedo /
 * pi
 */
#include <memory>

#include "core/technique/technique.h"
#include "ssvp_settings.h"

namespace gilab {

struct SsvpGpu;

class SsvpTechnique final : public Technique {
public:
    SsvpTechnique();
    ~SsvpTechnique() override;
    static TechniqueInfo describe();
    SupportResult checkSupport(const Scene& scene, const ParamSet& params) const override;
    void setup(TechniqueContext& ctx) override;
    void onParamsChanged(TechniqueContext& ctx, const std::vector<std::string>& keys) override;
    UpdateKind update(TechniqueContext& ctx, const SceneChanges& changes) override;
    void render(TechniqueContext& ctx, VkCommandBuffer cmd, FrameTargets& targets) override;
    void frameFinished(TechniqueContext& ctx) override;
    std::vector<DebugView> debugViews() override;
    bool readVplSet(VplSet& out) override;
    /** The last frame's K-means converged (a pass changed no assignment). */
    bool settled() const override { return m_kmeansConverged; }

private:
    void applySettings(const TechniqueContext& ctx);

    SsvpSettings m_settings;
    std::unique_ptr<SsvpGpu> m_gpu;
    bool m_kmeansConverged = false;
};

}  // namespace gilab
