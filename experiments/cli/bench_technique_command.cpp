// `gilab bench technique`: set-up and per-frame GPU time of techniques on one scene, per pass,
// printed as a table (a benchmark command, not a timed test; docs/timing.md).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "core/passes/shared_passes.h"
#include "core/scene/scene_loader.h"
#include "core/technique/frame_harness.h"
#include "core/technique/registry.h"
#include "core/util/error.h"
#include "core/util/progress.h"
#include "core/vk/context.h"
#include "experiments/cli/cli.h"
#include "experiments/runner/run_metadata.h"

namespace gilab::cli {
namespace {

struct Quartiles {
    double median = NAN, iqr = NAN;
};

Quartiles quartiles(std::vector<double> v) {
    if (v.empty()) return {};
    std::sort(v.begin(), v.end());
    auto at = [&](double q) {
        const double x = q * double(v.size() - 1);
        const size_t i = size_t(x);
        const double f = x - double(i);
        return i + 1 < v.size() ? v[i] * (1.0 - f) + v[i + 1] * f : v[i];
    };
    return {at(0.5), at(0.75) - at(0.25)};
}

void benchOne(vk::Context& ctx, const Scene& scene, const std::string& id,
              const BenchTechniqueOptions& options) {
    ParamSet params = TechniqueRegistry::instance().defaultParams(id);
    ParamSet shared = defaultSharedParams();
    applyAssignments(options.assignments, params, shared);
    checkParamValues(id, params, shared);  // cross-parameter rules: exit 2
    FrameHarness harness(ctx, scene, id, params, shared);
    if (!harness.support().supported) {
        std::printf("%-8s unsupported: %s\n", id.c_str(), harness.support().reason.c_str());
        return;
    }
    Progress progress("bench " + id, size_t(options.warmupFrames + options.frames));
    const SetupTiming setup = harness.setup();
    std::vector<double> frameGpu;
    std::map<std::string, std::vector<double>> passes;
    std::vector<std::string> order;
    const WarmupResult warmup = harness.warmUp(options.warmupFrames, [&](int i) {
        progress.update(size_t(std::min(i + 1, options.warmupFrames)));
    });
    if (!warmup.settled)
        std::printf("%-8s not settled after %d warm-up frames\n", id.c_str(), warmup.run);
    for (int i = options.warmupFrames; i < options.warmupFrames + options.frames; ++i) {
        const FrameTiming t = harness.renderFrame();
        progress.update(size_t(i + 1));
        double sum = 0.0;
        for (const vk::PassTime& p : t.passes) {
            if (!passes.count(p.name)) order.push_back(p.name);
            passes[p.name].push_back(p.gpuMs);
            if (!isDiagnosticPass(p.name)) sum += p.gpuMs;
        }
        frameGpu.push_back(sum);
    }
    progress.finish();
    const Quartiles frame = quartiles(frameGpu);
    std::printf("%-8s set-up %9.1f ms (technique %.1f)   frame GPU %8.2f ms (IQR %.2f)\n",
                id.c_str(), setup.totalMs, setup.techniqueSetupMs, frame.median, frame.iqr);
    for (const vk::PassTime& p : setup.passes)
        std::printf("           set-up %-28s %9.2f ms\n", p.name.c_str(), p.gpuMs);
    for (const std::string& name : order) {
        const Quartiles q = quartiles(passes[name]);
        std::printf("           frame  %-28s %9.2f ms (IQR %.2f)\n", name.c_str(), q.median, q.iqr);
    }
}

}  // namespace

int runBenchTechnique(const BenchTechniqueOptions& options) {
    Progress::setQuiet(options.quiet);
    Scene scene = loadSceneOrDefault(options.scenePath);
    applyResolutionOverride(scene, options.resolution);
    std::vector<std::string> ids = options.techniques;
    if (ids.empty())
        for (const TechniqueInfo* info : TechniqueRegistry::instance().list())
            ids.push_back(info->id);
    for (const std::string& id : ids)
        (void)TechniqueRegistry::instance().get(id);  // unknown ids fail before any GPU work
    vk::ContextOptions ctxOptions;
    ctxOptions.deviceFilter = options.device;
    vk::Context ctx(ctxOptions);
    std::printf("%s, %dx%d, %s; median of %d frames after %d warm-up (GPU timestamps)\n",
                scene.name.c_str(), scene.settings.width, scene.settings.height,
                ctx.deviceName().c_str(), options.frames, options.warmupFrames);
    for (const std::string& id : ids)
        benchOne(ctx, scene, id, options);
    return kExitOk;
}

}  // namespace gilab::cli
