#pragma once
/**
 * Random point and spot light placements for `gilab bench direct --placements N` (issue 43):
 * lights the shadow code was not tuned on, near walls and in cluttered corners.
 *
 * Placement k of a scene: a camera ray through a random pixel hits a surface at p (normal n
 * turned toward the camera); the light sits at p + d n, d log-uniform in [0.002, 0.2] x the
 * scene's diagonal (shortened to half the free distance along n), so short d puts it against a
 * wall or into a corner. Even k: a point light; odd k: a spot aimed at the hit point of another
 * random camera ray, outer cone 20-70 deg, inner 0.8 x outer. Intensity (0.1 diagonal)^2 W/sr.
 * Deterministic in (scene, seed, k).
 */
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/scene/scene.h"

namespace gilab::cli {

struct LightPlacement {
    Light light;
    std::string label;  // "point (x, y, z)" or "spot (x, y, z) -> (x, y, z), 45 deg"
};

/** Placements 0..count-1 (fewer when the camera sees no surface along the tried rays). */
std::vector<LightPlacement> randomLightPlacements(const Scene& scene, uint32_t seed,
                                                  uint32_t count);

/** The scene lit by `light` alone: its lights replaced, its emissive materials turned off. */
Scene withOnlyLight(const Scene& scene, const Light& light);

}  // namespace gilab::cli
