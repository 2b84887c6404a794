#pragma once
/**
 * Emitter samples: K virtual point lights that stand in for the scene's emissive triangles in
 * the rasteriser (docs/shared_passes.md, "Area lights").
 *
 * Each sample sits at a point y of an emissive triangle with unit normal n (counter-clockwise
 * side), radiance Le (emissive factor x emissive texture at y) and represents an area A_k, so it
 * emits the cosine-lobe intensity
 *     I(w) = Le * A_k * max(0, dot(n, w))      [W/sr]      (|dot(n, w)| for double-sided)
 * and a receiver at distance r sees E = I(w) * cos(theta_receiver) / r^2. This is the quadrature
 *     E = integral Le cos(theta_y) cos(theta_x) / r^2 dA  ~=  sum_k Le_k A_k cos cos / r_k^2,
 * which converges to the exact area light as K -> infinity.
 *
 * Allocation (deterministic): the K samples are stratified over the emissive triangles by power
 * Phi_i = luminance(Le_i) * area_i (x 2 when double-sided), Le_i the triangle's mean radiance
 * (meanTriangleEmission, core/scene/emission.h): sample k goes to the triangle whose
 * cumulative power share contains (k + 0.5) / K. A triangle with n_i samples places them at n_i
 * Hammersley points warped uniformly onto it, each with A_k = area_i / n_i, so every sampled
 * triangle keeps its power exactly. Triangles that get no sample (power share < 1/K) have their
 * power spread over all samples (a common scale), so the total emitted power is exact for any K.
 */
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace gilab {

struct Scene;

struct EmitterSample {
    glm::vec3 position{0.0f};
    glm::vec3 normal{0.0f, 1.0f, 0.0f};  // unit, counter-clockwise side
    glm::vec3 intensity{0.0f};           // Le * A_k: W/sr along the normal
    float area = 0.0f;                   // A_k, m^2 (before the power scale)
    bool twoSided = false;
    uint32_t triangle = 0;
};

/**
 * An emissive triangle for the direct pass's exact unoccluded irradiance (Lambert's polygon
 * formula, docs/shared_passes.md "Area lights"): its vertices (counter-clockwise), its radiance
 * (emissive factor x the mean of its emissive texture over the triangle's uv footprint) and
 * whether both faces emit.
 */
struct EmitterPolygon {
    glm::vec3 p0{0.0f}, p1{0.0f}, p2{0.0f};
    glm::vec3 radiance{0.0f};
    bool twoSided = false;
};

/** Emissive triangles with a non-zero area and radiance. */
size_t countEmitterTriangles(const Scene& scene);

/** Every emissive triangle with a non-zero area and radiance, in triangle order. */
std::vector<EmitterPolygon> buildEmitterPolygons(const Scene& scene);

/** `count` samples (none when count == 0 or the scene has no emitter). */
std::vector<EmitterSample> buildEmitterSamples(const Scene& scene, uint32_t count);

}  // namespace gilab
