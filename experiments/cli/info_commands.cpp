// `gilab devices` and `gilab scene-info`.
#include <cstdio>

#include <nlohmann/json.hpp>

#include "core/scene/scene_loader.h"
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

int runSceneInfo(const std::string& scenePath, bool json) {
    const Scene scene = loadSceneOrDefault(scenePath);
    const nlohmann::ordered_json info = sceneToJson(scene);
    if (json) {
        std::printf("%s\n", info.dump(2).c_str());
        return kExitOk;
    }
    const SceneCaps& c = scene.caps;
    std::printf("scene %s (%s)\n", scene.name.c_str(), scene.sourcePath.c_str());
    std::printf("  %zu triangles (%zu emissive), %zu materials, %zu textures, %zu lights\n",
                c.triangleCount, c.emissiveTriangleCount, scene.materials.size(),
                scene.textures.size(), scene.lights.size());
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
    for (const std::string& w : scene.warnings)
        std::printf("  warning: %s\n", w.c_str());
    return kExitOk;
}

}  // namespace gilab::cli
