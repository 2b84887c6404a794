#pragma once
/**
 * View-fitted cascades of a directional light's shadow map (cascaded shadow maps, Engel 2006;
 * the split scheme of parallel-split shadow maps, Zhang et al. 2006).
 *
 * The camera's depth range is first clipped to the scene's bounding box (the depths of its
 * corners), then cut into `count` slices at
 *   z_i = lambda * n * (f / n)^(i / count) + (1 - lambda) * (n + (f - n) * i / count).
 * Each cascade is an orthographic map over the light-space rectangle of its slice's frustum,
 * clipped to the light-space rectangle of the scene box and widened by a margin of texels (for
 * PCF taps). With `snap` (default) each half-extent is rounded up to a quarter-octave step of the
 * light's radius and the centre to a whole texel, so the texel grid does not move with the camera.
 * Every cascade keeps the light's whole-scene depth range: distances are measured from the entry
 * plane of the scene's bounding sphere, as in the light's own map, so occluders outside the
 * camera's view still cast. docs/shared_passes.md has the measured defaults.
 */
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "core/scene/camera.h"
#include "core/scene/scene.h"

namespace gilab {

/** A directional light's view of the scene: distances along `direction` from the entry plane
 *  through `origin`, over the depth range [0, 2 * radius]. */
struct OrthoLightFrame {
    glm::vec3 origin{0.0f};
    glm::vec3 direction{0.0f, -1.0f, 0.0f};
    float radius = 1.0f;
};

struct ShadowCascade {
    glm::mat4 viewProj{1.0f};  // world -> Vulkan clip (y down), depth = 1 - distance / (2r)
    float texel = 0.0f;        // world size of the larger side of a texel
    float nearDepth = 0.0f;    // camera depth range of the slice it was fitted to
    float farDepth = 0.0f;
};

struct CascadeSettings {
    uint32_t count = 4;
    float split = 0.5f;  // lambda: 0 uniform, 1 logarithmic
    uint32_t resolution = 1024;
    uint32_t marginTexels = 2;  // border kept free for PCF taps
    bool snap = true;  // quarter-octave sizes and whole-texel centres (stable under camera motion)
};

/** The whole-scene orthographic view-projection (the light's own map), y down. */
glm::mat4 orthoSceneViewProj(const OrthoLightFrame& frame);

/**
 * Exactly `settings.count` cascades (empty if the count is 0). If the camera sees none of the
 * scene box, every cascade covers the box's whole light-space rectangle.
 */
std::vector<ShadowCascade> fitShadowCascades(const Camera& camera, float aspect,
                                             const Bounds& sceneBox, const OrthoLightFrame& frame,
                                             const CascadeSettings& settings);

}  // namespace gilab
