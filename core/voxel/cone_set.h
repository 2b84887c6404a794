#pragma once
/**
 * Diffuse cone sets for voxel cone tracing (docs/voxel_cone_tracing.md): one cone along the
 * normal plus a ring of tilted cones, weighted by the cosine-weighted solid angle each cone
 * covers and normalised so that sum(w) = pi (notes 003 E14). Mirrored in
 * shaders/common/cone_set.glsl through GpuConeSet.
 */
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace gilab {

/** One cone in tangent space (+z = surface normal); direction unit. */
struct VoxelCone {
    glm::vec3 direction;
    float weight;
};

struct ConeSet {
    std::vector<VoxelCone> cones;
    float apertureRad = 0.0f;  // full apex angle
};

/** Azimuth (radians) of the first ring cone for a ring of `ringCount` cones: (pi/4) / ringCount.
 *  No ring cone then lies along the tangent frame's axes (the frame follows the world axes, so
 *  an axis-aligned ring would aim every ring cone of an axis-aligned room at its walls; issue 9).
 */
float ringAzimuthOffset(uint32_t ringCount);

/** One cone along the normal, then count-1 tilted by tiltDeg at equal azimuth steps (rotated by
 *  ringAzimuthOffset); weights
 *  ~ cosine-weighted solid angle of each cone, normalised so sum w = pi. count in [1,16], aperture
 *  in (0,180) deg, tilt in [0,90) deg; tiltDeg < 0 = default (60 deg, notes 003 §8). Throws
 *  gilab::Error naming the argument. */
ConeSet makeDiffuseConeSet(uint32_t count, float apertureDeg, float tiltDeg = -1.0f);

inline constexpr uint32_t kMaxCones = 16;
inline constexpr float kDefaultConeTiltDeg = 60.0f;

/** Mirrors ConeSetData in shaders/common/cone_set.glsl (std140/std430 compatible). */
struct GpuConeSet {
    glm::vec4 cones[kMaxCones];  // xyz direction (tangent space), w weight
    glm::vec4 info;              // x cone count, y tan(aperture / 2), zw unused
};
static_assert(sizeof(GpuConeSet) == 17 * 16);

/** Packs a set for the GPU; throws gilab::Error if it has more than kMaxCones cones. */
GpuConeSet toGpu(const ConeSet& set);

/** Cosine-weighted solid angle of a cone of half-angle `halfAngle` whose axis is tilted by
 *  `tilt` from the normal, clipped to the upper hemisphere (numerical integration). Exposed for
 *  tests and docs. */
float coneCosineWeightedSolidAngle(float halfAngle, float tilt);

}  // namespace gilab
