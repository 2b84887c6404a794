#pragma once
/**
 * The two cone tests of the topological VPLs (Noël & Biri 2014 §V-C/D; notes 004 E7, E8), the
 * C++ mirror of techniques/topovpl/shaders/topovpl.glsl that the CPU tests check: the conservative
 * sphere test of light assignment must accept every sphere that holds a point the exact test of
 * indirect lighting accepts.
 */
#include <algorithm>
#include <cmath>

#include <glm/glm.hpp>

namespace gilab::topo {

struct GateDisk {
    glm::vec3 centre{0.0f}, normal{0.0f, 0.0f, 1.0f};  // unit normal
    float radius = 0.0f;
};

/** (E7) Whether the segment from the VPL x to the receiver p crosses the disk strictly between
 *  its ends (parallel segments never do). */
inline bool throughGate(const glm::vec3& x, const glm::vec3& p, const GateDisk& g) {
    const float denom = glm::dot(g.normal, p - x);
    const float len = glm::length(p - x);
    if (std::abs(denom) <= 1e-6f * len) return false;
    const float t = glm::dot(g.normal, g.centre - x) / denom;
    if (!(t > 0.0f && t < 1.0f)) return false;
    const glm::vec3 q = x + t * (p - x) - g.centre;
    return glm::dot(q, q) <= g.radius * g.radius;
}

/** (E8) Whether the cone from x around the gate's bounding sphere reaches the sphere (s, rho)
 *  on the far side of the gate's plane. */
inline bool coneHitsSphere(const glm::vec3& x, const GateDisk& g, const glm::vec3& s, float rho) {
    const glm::vec3 farSide = g.normal * (glm::dot(g.normal, g.centre - x) >= 0.0f ? 1.0f : -1.0f);
    if (glm::dot(farSide, s - g.centre) <= -rho) return false;
    const glm::vec3 toC = g.centre - x;
    const float dc = glm::length(toC);
    if (dc <= g.radius) return true;
    const glm::vec3 toS = s - x;
    const float ds = glm::length(toS);
    if (ds <= rho) return true;
    const float beta = std::asin(std::min(1.0f, g.radius / dc));
    const float gamma = std::asin(std::min(1.0f, rho / ds));
    const float cosAngle = std::clamp(glm::dot(toC, toS) / (dc * ds), -1.0f, 1.0f);
    return std::acos(cosAngle) <= beta + gamma + 1e-5f;
}

}  // namespace gilab::topo
