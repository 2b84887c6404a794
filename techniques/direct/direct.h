#pragma once
/**
 * `direct`: direct light only, no global illumination. The zero point every GI technique is
 * compared with: its final image is emission + the shared direct-light pass, its indirect layer
 * is exactly zero. It has no parameters of its own; the shared passes' (shadow maps, PCF,
 * area-light samples) apply, as they do to every technique.
 */
#include "core/technique/technique.h"

namespace gilab {

class DirectTechnique final : public Technique {
public:
    static TechniqueInfo describe();
    void setup(TechniqueContext& ctx) override;
    /** Nothing is precomputed: the shared passes follow the lights and camera by themselves. */
    UpdateKind update(TechniqueContext& ctx, const SceneChanges& changes) override;
    void render(TechniqueContext& ctx, VkCommandBuffer cmd, FrameTargets& targets) override;
};

}  // namespace gilab
