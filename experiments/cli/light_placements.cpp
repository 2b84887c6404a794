#include "experiments/cli/light_placements.h"

#include <cmath>
#include <cstdio>
#include <random>

#include <glm/glm.hpp>

#include "reference/embree_scene.h"
#include "reference/texture_lookup.h"

namespace gilab::cli {
namespace {

struct SurfaceHit {
    glm::vec3 point, normal;
};

/** The first surface a camera ray through pixel (u, v) in [0, 1]^2 meets. */
std::optional<SurfaceHit> cameraHit(const Scene& scene, const ref::EmbreeScene& embree, float u,
                                    float v) {
    const Camera& c = scene.camera;
    const float aspect = float(scene.settings.width) / float(std::max(scene.settings.height, 1));
    const float tanY = std::tan(0.5f * c.vfovRad);
    const glm::vec3 dir =
        glm::normalize(c.forward() + c.right() * ((2.0f * u - 1.0f) * tanY * aspect) +
                       c.trueUp() * ((1.0f - 2.0f * v) * tanY));
    ref::RayHit hit;
    if (!embree.intersect(c.position, dir, 0.0f, 1e30f, hit)) return std::nullopt;
    glm::vec3 n = embree.triangle(hit.prim).n;
    if (glm::dot(n, dir) > 0.0f) n = -n;
    return SurfaceHit{c.position + hit.t * dir, n};
}

std::string vec(const glm::vec3& p) {
    char text[96];
    std::snprintf(text, sizeof(text), "(%.3f, %.3f, %.3f)", p.x, p.y, p.z);
    return text;
}

std::optional<LightPlacement> placement(const Scene& scene, const ref::EmbreeScene& embree,
                                        uint32_t seed, uint32_t k) {
    std::mt19937 rng(seed * 7919u + k * 104729u + uint32_t(std::hash<std::string>{}(scene.name)));
    std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
    const Bounds& b = scene.caps.bounds;
    const float diagonal = glm::length(b.hi - b.lo);
    auto anyHit = [&]() -> std::optional<SurfaceHit> {
        for (int tries = 0; tries < 64; ++tries)
            if (auto h = cameraHit(scene, embree, uniform(rng), uniform(rng))) return h;
        return std::nullopt;
    };
    const std::optional<SurfaceHit> at = anyHit();
    if (!at) return std::nullopt;
    float d = diagonal * 0.002f * std::pow(100.0f, uniform(rng));  // [0.002, 0.2] diagonal
    ref::RayHit free;
    if (embree.intersect(at->point + 1e-4f * diagonal * at->normal, at->normal, 0.0f, d, free))
        d = 0.5f * (free.t + 1e-4f * diagonal);
    LightPlacement out;
    Light& l = out.light;
    l.position = at->point + d * at->normal;
    const float strength = (0.1f * diagonal) * (0.1f * diagonal);
    l.color = glm::vec3(1.0f);
    l.strength = strength;
    l.intensity = glm::vec3(strength);
    if (k % 2 == 0) {
        l.type = LightType::Point;
        l.name = "placed_point";
        out.label = "point " + vec(l.position);
        return out;
    }
    const std::optional<SurfaceHit> target = anyHit();
    glm::vec3 aim = target ? target->point - l.position : -at->normal;
    if (!(glm::length(aim) > 1e-6f * diagonal)) aim = -at->normal;
    l.type = LightType::Spot;
    l.name = "placed_spot";
    l.direction = glm::normalize(aim);
    const float outerDeg = 20.0f + 50.0f * uniform(rng);
    l.outerConeRad = glm::radians(outerDeg);
    l.innerConeRad = 0.8f * l.outerConeRad;
    char cone[32];
    std::snprintf(cone, sizeof(cone), ", %.0f deg", double(outerDeg));
    out.label = "spot " + vec(l.position) + " -> " + vec(l.position + l.direction) + cone;
    return out;
}

}  // namespace

std::vector<LightPlacement> randomLightPlacements(const Scene& scene, uint32_t seed,
                                                  uint32_t count) {
    const ref::TextureLookup textures(scene.textures);
    const ref::EmbreeScene embree(scene, textures);
    std::vector<LightPlacement> out;
    for (uint32_t k = 0; k < count; ++k)
        if (auto p = placement(scene, embree, seed, k)) out.push_back(*p);
    return out;
}

Scene withOnlyLight(const Scene& scene, const Light& light) {
    Scene s = scene;
    s.lights = {light};
    for (Material& m : s.materials) {
        m.emissiveFactor = glm::vec3(0.0f);
        m.emissiveTexture = -1;
    }
    s.computeCaps();
    return s;
}

}  // namespace gilab::cli
