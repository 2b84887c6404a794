#pragma once
/**
 * `ddgi`: dynamic diffuse global illumination with ray-traced irradiance probes,
 * Z. Majercik, J.-P. Guertin, D. Nowrouzezahrai, M. McGuire, JCGT 8(2), 2019, with probe
 * relocation and classification from Z. Majercik, A. Marrs, J. Spjut, M. McGuire, JCGT 10(2),
 * 2021. Extraction: notes 005; choices: techniques/ddgi/README.md.
 *
 * Set-up: the probe grid over the scene bounds, the atlases and the scene's BVH for the GPU ray
 * tracer (core/rt; CPU pass "ddgi/bvh_build"); no precomputation of light.
 * Per frame (all of it, every frame: a light or camera change costs what a static frame does):
 *   probe_trace             N rays per probe (spherical Fibonacci, random rotation per update),
 *                           hits shaded with direct light (shadow rays) + the previous irradiance
 *   probe_blend_irradiance  cosine-weighted mean, E^(1/gamma), hysteresis
 *   probe_blend_distance    cos^s-weighted distance moments, hysteresis
 *   probe_border            octahedral gutter copy
 *   probe_relocation        (relocation = true) offsets from the fixed rays
 *   probe_classification    (classification = true) active / inactive
 *   gather                  per-pixel 8-probe query with Chebyshev visibility -> indirect layer
 * The probes converge over updates (hysteresis): settled() reports when the mean irradiance has
 * stopped changing, so warm-up renders until then (docs/timing.md "Warm-up").
 */
#include <memory>
#include <vector>

#include "core/technique/technique.h"
#include "ddgi_settings.h"

namespace gilab {

class DdgiVolume;

class DdgiTechnique final : public Technique {
public:
    DdgiTechnique();
    ~DdgiTechnique() override;
    static TechniqueInfo describe();
    void setup(TechniqueContext& ctx) override;
    UpdateKind update(TechniqueContext& ctx, const SceneChanges& changes) override;
    void render(TechniqueContext& ctx, VkCommandBuffer cmd, FrameTargets& targets) override;
    void frameFinished(TechniqueContext& ctx) override;
    bool settled() const override { return m_settled; }

private:
    /** The hysteresis of the next update: the cold-start schedule, then the event frames. */
    float nextHysteresis(const DdgiSettings& s) const;
    void resetSettle();

    std::unique_ptr<DdgiVolume> m_volume;
    uint32_t m_updates = 0;      // updates since the cold start
    uint32_t m_updateIndex = 0;  // every update of this run (seeds the rotations)
    int m_eventFramesLeft = 0;
    bool m_settled = false;
    bool m_rampDone = false;      // the cold-start ramp ends when the probes first settle
    std::vector<double> m_means;  // mean irradiance after each update since the last reset
    int m_quietUpdates = 0;
};

}  // namespace gilab
