#pragma once
/**
 * What the vct GPU tests share (techniques/vct/tests/vct_test.cpp,
 * techniques/vct/tests/vct_injection_test.cpp): the Cornell box at a small size, vct parameters on
 * a 32^3 grid, and a VctTechnique set up outside the harness so tests can reach its injection and
 * radiance volumes.
 */
#include <initializer_list>
#include <string>
#include <utility>
#include <vector>

#include "core/gpu/gpu_scene.h"
#include "core/passes/shared_passes.h"
#include "core/scene/scene_loader.h"
#include "core/technique/registry.h"
#include "techniques/vct/vct.h"

namespace gilab::test {

inline Scene cornell(const std::string& variant, int size = 64) {
    Scene scene =
        loadSceneFile(std::string(GILAB_SOURCE_DIR) + "/scenes/cornell_box.json", variant);
    scene.settings.width = size;
    scene.settings.height = size;
    return scene;
}

inline ParamSet vctParams(std::initializer_list<std::pair<const char*, const char*>> values) {
    ParamSet p = TechniqueRegistry::instance().defaultParams("vct");
    p.set("voxel_resolution", "32");
    for (const auto& [k, v] : values)
        p.set(k, v);
    return p;
}

/** A VctTechnique set up outside the harness, so tests can reach its injection. */
struct VctRig {
    VctRig(vk::Context& vk, Scene s, ParamSet p)
        : scene(std::move(s)),
          params(std::move(p)),
          gpuScene(vk, scene),
          shared(vk, gpuScene, uint32_t(scene.settings.width), uint32_t(scene.settings.height)),
          ctx{vk,
              scene,
              gpuScene,
              shared,
              params,
              uint32_t(scene.settings.width),
              uint32_t(scene.settings.height),
              nullptr,
              &skipped,
              &notes,
              "vct",
              nullptr} {
        technique.setup(ctx);
    }
    Scene scene;
    ParamSet params;
    vk::GpuScene gpuScene;
    SharedPasses shared;
    std::vector<std::string> skipped, notes;
    TechniqueContext ctx;
    VctTechnique technique;
};

}  // namespace gilab::test
