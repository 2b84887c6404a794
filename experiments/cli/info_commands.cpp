// `gilab devices` and `gilab scene-info`.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/scene/emission.h"
#include "core/scene/scene_loader.h"
#include "core/technique/registry.h"
#include "core/vk/context.h"
#include "experiments/cli/cli.h"
#include "experiments/runner/run_metadata.h"

namespace gilab::cli {

int runDevices(const std::string& device) {
    vk::ContextOptions options;
    options.deviceFilter = device;
    vk::Context ctx(options);
    for (const vk::DeviceCandidate& c : ctx.candidates())
        std::printf("%s %-40s %-10s %s\n", c.chosen ? "*" : " ", c.name.c_str(), c.type.c_str(),
                    c.reason.c_str());
    std::printf("driver: %s (%s), Vulkan %s\n", ctx.driverName().c_str(), ctx.driverInfo().c_str(),
                ctx.apiVersion().c_str());
    return kExitOk;
}

Scene loadSceneOrDefault(const std::string& path) {
    return loadScene(path);
}

namespace {

std::string vecText(const glm::dvec3& v) {
    char text[96];
    std::snprintf(text, sizeof text, "[%.4g %.4g %.4g]", v.x, v.y, v.z);
    return text;
}

/** One line per punctual light: type, name, where, which way, how strong. */
std::string lightText(const Light& l) {
    const double toDeg = 180.0 / M_PI;
    const std::string name = "'" + l.name + "'";
    switch (l.type) {
        case LightType::Point:
            return "point " + name + " at " + vecText(l.position) + ", intensity " +
                   vecText(l.intensity) + " W/sr";
        case LightType::Spot: {
            char cone[64];
            std::snprintf(cone, sizeof cone, ", cone %.3g/%.3g deg (inner/outer)",
                          l.innerConeRad * toDeg, l.outerConeRad * toDeg);
            return "spot " + name + " at " + vecText(l.position) + " toward " +
                   vecText(l.direction) + ", intensity " + vecText(l.intensity) + " W/sr" + cone;
        }
        case LightType::Directional:
            return "directional " + name + " toward " + vecText(l.direction) + ", irradiance " +
                   vecText(l.intensity) + " W/m^2";
    }
    return name;
}

/** Whether a technique runs on the scene with its default parameters, and why not: its own
 *  check (Technique::checkSupport) and the harness's (triangles, resolution). */
SupportResult checkTechniqueSupport(const std::string& id, const Scene& scene) {
    const TechniqueRegistry& registry = TechniqueRegistry::instance();
    SupportResult s = registry.create(id)->checkSupport(scene, registry.defaultParams(id));
    if (scene.triangleCount() == 0) s = {false, "the scene has no triangles"};
    if (scene.settings.width < 1 || scene.settings.height < 1)
        s = {false, "the scene's resolution is empty"};
    return s;
}

}  // namespace

int runSceneInfo(const std::string& scenePath, bool json) {
    const Scene scene = loadSceneOrDefault(scenePath);
    nlohmann::ordered_json info = sceneToJson(scene);
    const EmitterSummary emitters = computeEmitterSummary(scene);
    std::vector<std::pair<std::string, SupportResult>> support;
    for (const TechniqueInfo* t : TechniqueRegistry::instance().list())
        support.emplace_back(t->id, checkTechniqueSupport(t->id, scene));
    if (json) {
        info["emissive"] = {{"triangles", emitters.triangleCount},
                            {"area_m2", emitters.areaM2},
                            {"power_w", {emitters.powerW.x, emitters.powerW.y, emitters.powerW.z}}};
        info["variants"] = scene.variants;
        nlohmann::ordered_json techniques = nlohmann::ordered_json::array();
        for (const auto& [id, s] : support)
            techniques.push_back({{"id", id}, {"supported", s.supported}, {"reason", s.reason}});
        info["techniques"] = techniques;
        std::printf("%s\n", info.dump(2).c_str());
        return kExitOk;
    }
    const SceneCaps& c = scene.caps;
    std::printf("scene %s (%s)\n", scene.name.c_str(), scene.sourcePath.c_str());
    std::printf("  %zu triangles (%zu emissive), %zu materials, %zu textures\n", c.triangleCount,
                c.emissiveTriangleCount, scene.materials.size(), scene.textures.size());
    std::printf("  lights: %zu punctual (point, spot, directional)", scene.lights.size());
    if (emitters.triangleCount > 0)
        std::printf("; emissive surfaces: %zu triangles, %.4g m^2, power %s W\n",
                    emitters.triangleCount, emitters.areaM2, vecText(emitters.powerW).c_str());
    else
        std::printf("; no emissive surfaces\n");
    for (size_t i = 0; i < scene.lights.size(); ++i)
        std::printf("    light %zu: %s\n", i, lightText(scene.lights[i]).c_str());
    const Camera& cam = scene.camera;
    std::printf("  camera: position %s, target %s, up %s, vertical fov %.3g deg\n",
                vecText(cam.position).c_str(), vecText(cam.target).c_str(), vecText(cam.up).c_str(),
                cam.vfovRad * 180.0 / M_PI);
    std::printf("  bounds [%g %g %g] .. [%g %g %g]\n", c.bounds.lo.x, c.bounds.lo.y, c.bounds.lo.z,
                c.bounds.hi.x, c.bounds.hi.y, c.bounds.hi.z);
    std::printf("  features: %s\n", info["caps"]["features"].dump().c_str());
    std::printf("  resolution %dx%d, exposure %+g EV\n", scene.settings.width,
                scene.settings.height, scene.settings.exposureEv);
    if (scene.animation.animated()) {
        const SceneAnimation& a = scene.animation;
        std::string targets;
        for (const AnimationTrack& t : a.tracks)
            targets += (targets.empty() ? "" : ", ") + animationTarget(t);
        std::printf("  animation: %d frames over %g s, %zu track%s (%s)\n", a.frameCount,
                    a.duration, a.tracks.size(), a.tracks.size() == 1 ? "" : "s", targets.c_str());
    }
    if (scene.variants.empty()) {
        std::printf("  variants: none\n");
    } else {
        std::string names;
        for (const std::string& v : scene.variants)
            names += (names.empty() ? "" : ", ") + v;
        std::printf("  variants: %s (--scene %s#<variant>)\n", names.c_str(),
                    scene.sourcePath.c_str());
    }
    std::printf("  techniques (default parameters):\n");
    size_t width = 0;
    for (const auto& [id, s] : support)
        width = std::max(width, id.size());
    for (const auto& [id, s] : support)
        std::printf("    %-*s  %s%s\n", int(width), id.c_str(),
                    s.supported ? "supported" : "not supported: ", s.reason.c_str());
    for (const std::string& w : scene.warnings)
        std::printf("  warning: %s\n", w.c_str());
    return kExitOk;
}

}  // namespace gilab::cli
