#include "experiments/cli/leak_causes.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include "core/image/color.h"
#include "core/scene/camera.h"
#include "core/util/error.h"
#include "reference/embree_scene.h"
#include "reference/spawn.h"
#include "reference/texture_lookup.h"

namespace gilab::cli {
namespace {

/** Angle (radians, small-angle) of one texel at the centre of the light's map. */
float texelAngle(const Light& light, uint32_t resolution) {
    const float res = float(std::max(resolution, 1u));
    // Spot maps up to 85 deg: fov = 2 outer + 5 deg; wider spots and points use cube faces
    // (90 deg). shadow_maps.h.
    const float outer = light.outerConeRad;
    if (light.type == LightType::Spot && outer <= glm::radians(85.0f))
        return 2.0f * std::tan(std::min(outer + glm::radians(2.5f), glm::radians(85.0f))) / res;
    return 2.0f / res;
}

/** Two unit vectors orthogonal to unit w. */
std::pair<glm::vec3, glm::vec3> basis(const glm::vec3& w) {
    const glm::vec3 guide = std::abs(w.y) < 0.9f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0);
    const glm::vec3 s = glm::normalize(glm::cross(guide, w));
    return {s, glm::cross(w, s)};
}

}  // namespace

LeakCauses classifyLeaks(const Scene& scene, const Image& raster, const Image& reference,
                         const ShadowModel& model) {
    if (scene.lights.empty() ||
        (scene.lights[0].type != LightType::Point && scene.lights[0].type != LightType::Spot))
        throw Error("classifyLeaks: the scene's first light must be a point or spot light");
    if (raster.width() != reference.width() || raster.height() != reference.height() ||
        raster.channels() < 3 || reference.channels() < 3)
        throw Error("classifyLeaks: images of different sizes or fewer than 3 channels");
    const Light& light = scene.lights[0];
    const ref::TextureLookup textures(scene.textures);
    const ref::EmbreeScene embree(scene, textures);
    const Bounds& b = scene.caps.bounds;
    const float radius = b.valid() ? std::max(0.5f * glm::length(b.extent()), 1e-3f) : 1.0f;
    const float nearZ = 1e-3f * radius;  // ShadowMaps::sceneFrame
    const float angle = texelAngle(light, model.resolution);
    const PrimaryRays rays(scene.camera, raster.width(), raster.height());
    const ref::SpawnOffsets spawn(embree);

    LeakCauses out;
    for (int y = 0; y < raster.height(); ++y)
        for (int x = 0; x < raster.width(); ++x) {
            const float r =
                luminance(reference.at(x, y, 0), reference.at(x, y, 1), reference.at(x, y, 2));
            const float t = luminance(raster.at(x, y, 0), raster.at(x, y, 1), raster.at(x, y, 2));
            if (!(r <= 0.0f) || !(t > 0.0f) || !std::isfinite(t)) continue;
            ++out.pixels;
            out.total += t;
            const Ray ray = rays(float(x) + 0.5f, float(y) + 0.5f);
            ref::RayHit hit;
            if (!embree.intersect(ray.origin, ray.direction, 0.0f, 1e30f, hit)) {
                out.background += t;
                continue;
            }
            // The path tracer's receiver: its shadow ray leaves from the spawn origin (spawn.h)
            const ref::MeshTriangle& tri = embree.triangle(hit.prim);
            const glm::vec3 o =
                spawn.origin(ref::exactHitPoint(tri, ray.origin, ray.direction, hit.u, hit.v),
                             hit.prim, -ray.direction);
            const glm::vec3 n = glm::dot(tri.n, ray.direction) > 0.0f ? -tri.n : tri.n;
            const glm::vec3 toLight = light.position - o;
            if (glm::dot(n, toLight) <= 0.0f) {  // the seen side faces away from the light
                out.backFacing += t;
                continue;
            }
            if (!embree.occluded(o, toLight, 0.0f, 1.0f - 1e-5f)) {  // integrator.cpp's test
                out.notOccluded += t;
                continue;
            }
            // What the map holds: the first surface from the light along the receiver's ray
            const float distance = glm::length(toLight);
            const glm::vec3 w = -toLight / distance;
            ref::RayHit occluder;
            if (!embree.intersect(light.position, w, 0.0f, distance, occluder))
                occluder.t = distance;  // caught within float margins of the receiver
            const float texel = angle * distance;
            if (occluder.t < nearZ) {
                out.nearPlane += t;
            } else if (distance - occluder.t < (model.constantBias + 1.0f) * texel) {
                out.contact += t;
            } else {
                // One texel's rays: does an occluder's outline cross the receiver's texel?
                const auto [s, u] = basis(w);
                int blocked = 0;
                for (int j = -1; j <= 1; ++j)
                    for (int i = -1; i <= 1; ++i) {
                        const glm::vec3 d =
                            glm::normalize(w + (0.5f * angle) * (float(i) * s + float(j) * u));
                        ref::RayHit h;
                        const float until = distance - (model.constantBias + 1.0f) * texel;
                        if (embree.intersect(light.position, d, 0.0f, until, h)) ++blocked;
                    }
                (blocked < 9 ? out.texelEdge : out.unexplained) += t;
            }
        }
    return out;
}

std::string describeLeakCauses(const LeakCauses& c) {
    if (!(c.total > 0.0)) return "no leaked light";
    std::vector<std::pair<double, const char*>> parts{
        {c.texelEdge, "occluder outline within a texel"},
        {c.contact, "contact"},
        {c.nearPlane, "near plane"},
        {c.notOccluded, "not occluded"},
        {c.backFacing, "back-facing"},
        {c.background, "background"},
        {c.unexplained, "unexplained"}};
    std::stable_sort(parts.begin(), parts.end(),
                     [](const auto& a, const auto& b) { return a.first > b.first; });
    std::string out;
    for (const auto& [value, name] : parts) {
        if (!(value > 0.0)) continue;
        char text[64];
        std::snprintf(text, sizeof(text), "%s%s %.0f %%", out.empty() ? "" : ", ", name,
                      100.0 * value / c.total);
        out += text;
    }
    return out + " (" + std::to_string(c.pixels) + " px)";
}

}  // namespace gilab::cli
