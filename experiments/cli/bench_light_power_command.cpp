// `gilab bench light-power`: each punctual light's emitted, incident and reflected power traced
// with Embree (reference/light_power.h), the control for the power a voxel volume holds
// (docs/techniques/vct.md, "Energy against the grid resolution").
#include <cstdio>

#include "core/scene/scene_loader.h"
#include "experiments/cli/cli.h"
#include "reference/light_power.h"

namespace gilab::cli {

int runBenchLightPower(const BenchLightPowerOptions& options) {
    std::printf("%-40s %-20s %12s %12s %12s %10s\n", "scene", "light", "emitted W", "incident W",
                "reflected W", "rays");
    for (const std::string& spec : options.scenes) {
        const Scene scene = loadScene(spec);
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
