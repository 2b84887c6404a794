#include "core/scene/scene.h"

#include <string>

#include "core/util/error.h"

namespace gilab {

void Scene::computeCaps() {
    caps = SceneCaps{};
    caps.triangleCount = triangleCount();
    if (indices.size() % 3 != 0 || triangleMaterials.size() != caps.triangleCount) {
        throw Error(name + ": scene has " + std::to_string(indices.size()) + " indices and " +
                    std::to_string(triangleMaterials.size()) + " triangle materials");
    }
    for (const Vertex& v : vertices)
        caps.bounds.extend(v.position);

    // Only materials that some triangle uses count towards the flags.
    std::vector<bool> used(materials.size(), false);
    for (size_t t = 0; t < caps.triangleCount; ++t) {
        const uint32_t m = triangleMaterials[t];
        if (m >= materials.size()) {
            throw Error(name + ": triangle " + std::to_string(t) + " uses material " +
                        std::to_string(m) + " of " + std::to_string(materials.size()));
        }
        used[m] = true;
        if (materials[m].isEmissive()) ++caps.emissiveTriangleCount;
    }
    caps.hasEmissive = caps.emissiveTriangleCount > 0;
    for (size_t m = 0; m < materials.size(); ++m) {
        if (!used[m]) continue;
        const Material& mat = materials[m];
        caps.hasGlossy = caps.hasGlossy || mat.isGlossy();
        caps.hasTextures = caps.hasTextures || mat.baseColorTexture >= 0 ||
                           mat.metallicRoughnessTexture >= 0 || mat.emissiveTexture >= 0;
        caps.hasAlphaMask = caps.hasAlphaMask || mat.alphaMode != AlphaMode::Opaque;
    }
    for (const Light& light : lights) {
        caps.hasPointLights = caps.hasPointLights || light.type == LightType::Point;
        caps.hasSpotLights = caps.hasSpotLights || light.type == LightType::Spot;
        caps.hasDirectionalLights =
            caps.hasDirectionalLights || light.type == LightType::Directional;
    }
}

void translateScene(Scene& scene, const glm::dvec3& t) {
    auto moved = [&](const glm::vec3& p) { return glm::vec3(glm::dvec3(p) + t); };
    for (Vertex& v : scene.vertices)
        v.position = moved(v.position);
    for (Light& l : scene.lights)
        if (l.type != LightType::Directional) l.position = moved(l.position);
    scene.camera.position = moved(scene.camera.position);
    scene.camera.target = moved(scene.camera.target);
    scene.computeCaps();
}

glm::dvec3 renderOrigin(const Scene& scene) {
    const Bounds& b = scene.caps.bounds;
    if (!b.valid()) return glm::dvec3(0.0);
    const glm::dvec3 centre = 0.5 * (glm::dvec3(b.lo) + glm::dvec3(b.hi));
    const glm::dvec3 origin = glm::round(centre);
    const bool finite = !glm::any(glm::isnan(origin)) && !glm::any(glm::isinf(origin));
    return finite ? origin : glm::dvec3(0.0);
}

}  // namespace gilab
