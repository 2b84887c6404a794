#pragma once
/**
 * The shared VPL module (docs/vpl.md): virtual point lights and their clusters as the GPU stores
 * them. Mirrors Vpl / VplCluster in shaders/common/vpl.glsl (std430). Used by the screen-space VPL
 * propagation (Aranha et al.) and meant for every VPL technique (topological VPLs, instant
 * radiosity).
 *
 * Units (docs/conventions.md): a VPL carries a flux [W]; it is a cosine emitter with intensity
 * I(w) = flux max(0, n.w) / pi [W/sr], so a receiver at distance d gets the irradiance
 * E = flux cos(theta) cos(sigma) / (pi d^2) [W/m^2].
 */
#include <vector>

#include <glm/glm.hpp>

namespace gilab {

struct GpuVpl {
    glm::vec4 position{0.0f};  // xyz world, w 1 = valid
    glm::vec4 normal{0.0f};    // xyz unit normal, w visibility map layer (-1 = unshadowed)
    glm::vec4 flux{0.0f};      // rgb W, w bounce
};
static_assert(sizeof(GpuVpl) == 48);

struct GpuVplCluster {
    glm::vec4 position{0.0f};  // xyz map eye, w 1 = active
    glm::vec4 normal{0.0f};    // xyz unit axis, w member count
    glm::vec4 flux{0.0f};      // rgb summed member flux
    glm::vec4 mean{0.0f};      // xyz member mean (before the eye offset)
};
static_assert(sizeof(GpuVplCluster) == 64);

/**
 * A technique's VPLs of the last frame as its gather shades them, for the same-VPL reference
 * (reference/vpl_reference.h: the same VPLs with exact shadow rays, Noël & Biri 2014 Table II).
 */
struct VplSet {
    std::vector<GpuVpl> vpls;
    float clampDistance = 0.0f;         // d_min of the gather, world units (0 = none)
    glm::vec2 bounceScale{1.0f, 1.0f};  // flux multiplier of bounce-1 and bounce-2 VPLs
};

}  // namespace gilab
