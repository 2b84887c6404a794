#pragma once
/**
 * Form factors for cvgi's gather (Cosin Ayerbe & Patow 2022 §4.4, Fig. 5: "a differential area
 * form factor" between a voxel face and a cluster; the paper does not write it out, notes 000
 * §2.5 [R] and §8.6). Derivation and measured errors: techniques/cvgi/README.md, "Face-to-cluster
 * form factor".
 *
 * diskFormFactor is what the gather uses (the GLSL side must mirror it exactly);
 * polygonFormFactor is the exact reference it is tested against.
 */
#include <cmath>
#include <numbers>

#include <glm/glm.hpp>

namespace gilab::cvgi {

/**
 * Differential area (receiver) to a disk of area `sourceArea` (source), notes 000 §2.5 [R]:
 *   F = max(0, n_r.w) * max(0, -n_s.w) * A / (pi r^2 + A),   w = (source - receiver) / r
 * (cosines clamped to [0, 1]).
 * Exact for a coaxial disk facing the receiver (A / (pi h^2 + A) = R^2 / (h^2 + R^2)); off axis
 * the two cosines are applied to the whole disk. Irradiance from a Lambertian source of
 * radiosity B: E = B * F. Finite and <= 1 for finite inputs with A >= 0; 0 when the points coincide
 * (r = 0, no direction).
 */
inline float diskFormFactor(glm::vec3 receiverPos, glm::vec3 receiverNormal, glm::vec3 sourcePos,
                            glm::vec3 sourceNormal, float sourceArea) {
    const glm::vec3 d = sourcePos - receiverPos;
    const float r2 = glm::dot(d, d);
    if (!(r2 > 0.f)) return 0.f;  // coincident points: no direction
    const glm::vec3 w = d / std::sqrt(r2);
    // Cosines clamped to [0, 1]: back-facing pairs give 0; rounding (denormal r) never gives > 1.
    const float cosR = glm::clamp(glm::dot(receiverNormal, w), 0.f, 1.f);
    const float cosS = glm::clamp(-glm::dot(sourceNormal, w), 0.f, 1.f);
    return cosR * cosS * sourceArea / (std::numbers::pi_v<float> * r2 + sourceArea);
}

/**
 * Exact differential area (at receiverPos, normal receiverNormal) to polygon form factor,
 * Lambert's contour integral: F = 1/(2 pi) |sum_i gamma_i n.(v_i x v_i+1)/|v_i x v_i+1||, v_i
 * the vertices relative to the receiver, gamma_i the angle between v_i and v_i+1. Valid for a
 * planar polygon entirely above the receiver's tangent plane; either winding (the absolute
 * value takes the orientation out). Computed in double.
 */
inline float polygonFormFactor(glm::vec3 receiverPos, glm::vec3 receiverNormal,
                               const glm::vec3* verts, int n) {
    const glm::dvec3 normal(receiverNormal);
    double sum = 0.0;
    for (int i = 0; i < n; ++i) {
        const glm::dvec3 a = glm::dvec3(verts[i]) - glm::dvec3(receiverPos);
        const glm::dvec3 b = glm::dvec3(verts[(i + 1) % n]) - glm::dvec3(receiverPos);
        const glm::dvec3 c = glm::cross(a, b);
        const double len = glm::length(c);
        if (len <= 0.0) continue;  // degenerate edge (repeated vertex or through the receiver)
        const double gamma = std::atan2(len, glm::dot(a, b));
        sum += gamma * glm::dot(normal, c) / len;
    }
    return float(std::abs(sum) / (2.0 * std::numbers::pi));
}

}  // namespace gilab::cvgi
