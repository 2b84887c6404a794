#include "core/voxel/cone_set.h"

#include <cmath>
#include <string>

#include <glm/gtc/constants.hpp>

#include "core/util/error.h"

namespace gilab {

float coneCosineWeightedSolidAngle(float halfAngle, float tilt) {
    // Integral of max(0, cos theta) over the cone, in cone-local polar coordinates (alpha, phi):
    // cos theta = cos(alpha) cos(tilt) + sin(alpha) sin(tilt) cos(phi), d omega = sin(alpha).
    // Midpoint rule; exact to ~1e-5 for our apertures (pi sin^2(h) cos(tilt) when unclipped).
    constexpr int kAlphaSteps = 96;
    constexpr int kPhiSteps = 192;
    const double h = double(halfAngle), ct = std::cos(double(tilt)), st = std::sin(double(tilt));
    const double da = h / kAlphaSteps, dp = 2.0 * glm::pi<double>() / kPhiSteps;
    double sum = 0.0;
    for (int i = 0; i < kAlphaSteps; ++i) {
        const double a = (i + 0.5) * da;
        const double ca = std::cos(a), sa = std::sin(a);
        double ring = 0.0;
        for (int j = 0; j < kPhiSteps; ++j) {
            const double c = ca * ct + sa * st * std::cos((j + 0.5) * dp);
            ring += c > 0.0 ? c : 0.0;
        }
        sum += ring * sa;
    }
    return float(sum * da * dp);
}

float ringAzimuthOffset(uint32_t ringCount) {
    // (pi/4 + 2 pi i) / m = k pi/2 has no integer solution (1 + 8i = 2km: odd = even), so no
    // ring cone of a ring of m lies on a tangent axis, for every m.
    return ringCount == 0 ? 0.0f : 0.25f * glm::pi<float>() / float(ringCount);
}

ConeSet makeDiffuseConeSet(uint32_t count, float apertureDeg, float tiltDeg) {
    if (count < 1 || count > kMaxCones) {
        throw Error("cone set: count = " + std::to_string(count) + " outside [1, " +
                    std::to_string(kMaxCones) + "]");
    }
    if (!(apertureDeg > 0.0f && apertureDeg < 180.0f)) {
        throw Error("cone set: aperture = " + std::to_string(apertureDeg) +
                    " deg outside (0, 180)");
    }
    if (std::isnan(tiltDeg) || tiltDeg >= 90.0f) {
        throw Error("cone set: tilt = " + std::to_string(tiltDeg) + " deg outside [0, 90)");
    }
    const float tilt = glm::radians(tiltDeg < 0.0f ? kDefaultConeTiltDeg : tiltDeg);
    ConeSet set;
    set.apertureRad = glm::radians(apertureDeg);
    const float half = 0.5f * set.apertureRad;
    // The normal cone, then a ring at equal azimuth steps (notes 003 §8 choice: true tilt),
    // rotated by ringAzimuthOffset so that no ring cone lies along a tangent axis.
    set.cones.push_back({glm::vec3(0.0f, 0.0f, 1.0f), coneCosineWeightedSolidAngle(half, 0.0f)});
    const float ringWeight = coneCosineWeightedSolidAngle(half, tilt);
    const float offset = ringAzimuthOffset(count - 1);
    for (uint32_t i = 1; i < count; ++i) {
        const float phi = offset + 2.0f * glm::pi<float>() * float(i - 1) / float(count - 1);
        glm::vec3 d(std::sin(tilt) * std::cos(phi), std::sin(tilt) * std::sin(phi), std::cos(tilt));
        set.cones.push_back({glm::normalize(d), ringWeight});
    }
    // Normalise to sum w = pi = integral of cos over the hemisphere (notes 003 E14).
    float total = 0.0f;
    for (const VoxelCone& c : set.cones)
        total += c.weight;
    if (!(total > 0.0f)) throw Error("cone set: zero total weight (aperture too small)");
    for (VoxelCone& c : set.cones)
        c.weight *= glm::pi<float>() / total;
    return set;
}

GpuConeSet toGpu(const ConeSet& set) {
    if (set.cones.size() > kMaxCones) {
        throw Error("cone set: " + std::to_string(set.cones.size()) + " cones, at most " +
                    std::to_string(kMaxCones));
    }
    GpuConeSet gpu{};
    for (size_t i = 0; i < set.cones.size(); ++i)
        gpu.cones[i] = glm::vec4(set.cones[i].direction, set.cones[i].weight);
    gpu.info = glm::vec4(float(set.cones.size()), std::tan(0.5f * set.apertureRad), 0.0f, 0.0f);
    return gpu;
}

}  // namespace gilab
