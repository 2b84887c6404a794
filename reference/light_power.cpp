#include "reference/light_power.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <glm/glm.hpp>

#include "reference/embree_scene.h"
#include "reference/lights.h"
#include "reference/texture_lookup.h"

namespace gilab::ref {
namespace {

constexpr double kPi = std::numbers::pi;

double mean(const glm::dvec3& v) {
    return (v.x + v.y + v.z) / 3.0;
}

/** Two unit vectors orthogonal to unit w. */
void basis(const glm::vec3& w, glm::vec3& s, glm::vec3& t) {
    const glm::vec3 guide = std::abs(w.y) < 0.9f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0);
    s = glm::normalize(glm::cross(guide, w));
    t = glm::cross(w, s);
}

/** Point i of n on [0, 1)^2: a Fibonacci lattice (stratified in both axes). */
glm::dvec2 lattice(uint32_t i, uint32_t n) {
    const double golden = 0.6180339887498949;
    return {(double(i) + 0.5) / double(n), std::fmod(double(i) * golden, 1.0)};
}

}  // namespace

std::vector<LightPower> punctualLightPower(const Scene& scene, uint32_t rays) {
    const TextureLookup textures(scene.textures);
    const EmbreeScene mesh(scene, textures);
    const Bounds& b = scene.caps.bounds;
    const glm::vec3 centre = b.valid() ? b.center() : glm::vec3(0.0f);
    const float radius = b.valid() ? std::max(0.5f * glm::length(b.extent()), 1e-3f) : 1.0f;
    rays = std::max(rays, 1u);
    std::vector<LightPower> out;
    for (size_t li = 0; li < scene.lights.size(); ++li) {
        const Light& light = scene.lights[li];
        LightPower p;
        p.light = light.name.empty() ? "light " + std::to_string(li) : light.name;
        p.rays = rays;
        const glm::dvec3 intensity(light.intensity);
        const double cosOuter = std::cos(double(light.outerConeRad));
        const float cosInnerF = std::cos(light.innerConeRad), cosOuterF = float(cosOuter);
        glm::vec3 s, t;
        const glm::vec3 axis =
            light.type == LightType::Point ? glm::vec3(0, 0, 1) : glm::normalize(light.direction);
        basis(axis, s, t);
        for (uint32_t i = 0; i < rays; ++i) {
            const glm::dvec2 u = lattice(i, rays);
            glm::vec3 origin, dir;
            glm::dvec3 flux;
            if (light.type == LightType::Directional) {
                // A disk of the bounding sphere's radius, perpendicular to the light, upstream
                const double r = double(radius) * std::sqrt(u.x), phi = 2.0 * kPi * u.y;
                origin = centre - 2.0f * radius * axis + float(r * std::cos(phi)) * s +
                         float(r * std::sin(phi)) * t;
                dir = axis;
                flux = intensity * (kPi * double(radius) * radius / double(rays));
            } else {
                // Uniform over the sphere (point) or the outer cone (spot), by solid angle
                const double zMin = light.type == LightType::Point ? -1.0 : cosOuter;
                const double z = 1.0 - u.x * (1.0 - zMin), phi = 2.0 * kPi * u.y;
                const double rr = std::sqrt(std::max(0.0, 1.0 - z * z));
                dir = glm::normalize(float(rr * std::cos(phi)) * s + float(rr * std::sin(phi)) * t +
                                     float(z) * axis);
                origin = light.position;
                const double solidAngle = 2.0 * kPi * (1.0 - zMin) / double(rays);
                const double lobe = light.type == LightType::Spot
                                        ? double(spotFalloff(float(z), cosInnerF, cosOuterF))
                                        : 1.0;
                flux = intensity * (lobe * solidAngle);
            }
            p.emittedW += mean(flux);
            RayHit hit;
            if (!mesh.intersect(origin, dir, 0.0f, 1e30f, hit)) continue;
            const MeshTriangle& tri = mesh.triangle(hit.prim);
            const glm::vec4 albedo =
                lookupBaseColor(scene.materials[tri.material], textures, tri.uvAt(hit.u, hit.v));
            p.incidentW += mean(flux);
            p.reflectedW += mean(glm::dvec3(albedo) * flux);
        }
        out.push_back(p);
    }
    return out;
}

}  // namespace gilab::ref
