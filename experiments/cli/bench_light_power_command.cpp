// `gilab bench light-power`: each punctual light's emitted, incident and reflected power traced
// with Embree (reference/light_power.h), the control for the power a voxel volume holds
// (techniques/vct/README.md, "Energy against the grid resolution").
#include <cstdio>
#include <vector>

#include "core/scene/scene_loader.h"
#include "experiments/cli/cli.h"
#include "reference/light_power.h"

namespace gilab::cli {

int runBenchLightPower(const BenchLightPowerOptions& options) {
    std::vector<Scene> scenes;  // every scene loads (or fails with its error) before any output
    for (const std::string& spec : options.scenes)
        scenes.push_back(loadScene(spec));
    std::printf("%-40s %-20s %12s %12s %12s %10s\n", "scene", "light", "emitted W", "incident W",
                "reflected W", "rays");
    for (size_t k = 0; k < scenes.size(); ++k) {
        const Scene& scene = scenes[k];
        const std::string& spec = options.scenes[k];
        if (scene.lights.empty()) std::printf("%-40s (no punctual light)\n", spec.c_str());
        if (scene.caps.hasEmissive)
            std::printf("%-40s (emissive triangles are not counted)\n", spec.c_str());
        for (const ref::LightPower& p : ref::punctualLightPower(scene, options.rays))
            std::printf("%-40s %-20s %12.5g %12.5g %12.5g %10llu\n", spec.c_str(), p.light.c_str(),
                        p.emittedW, p.incidentW, p.reflectedW, (unsigned long long)p.rays);
    }
    std::printf(
        "mean of rgb; reflected = base colour x texture at the first hit x the flux there "
        "(what vct's power_photons_reflected_w and cvgi's lit_power_w should hold)\n");
    return kExitOk;
}

}  // namespace gilab::cli
