#include "experiments/runner/pt_baseline.h"

#include <chrono>
#include <thread>

#include "core/technique/registry.h"
#include "core/util/error.h"
#include "experiments/runner/run_metadata.h"
#include "reference/path_tracer.h"

namespace gilab::exp {
namespace {

double msSince(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
        .count();
}

std::vector<ImageLayer> baselineLayers(const ref::Accumulator& acc) {
    const Image full = ref::meanImage(acc, ref::Layer::Full);
    const Image emission = ref::meanImage(acc, ref::Layer::Emission);
    const Image direct = ref::meanImage(acc, ref::Layer::Direct);
    Image indirect = full;
    std::vector<float>& v = indirect.values();
    for (size_t i = 0; i < v.size(); ++i)
        v[i] = full.values()[i] - emission.values()[i] - direct.values()[i];
    return {{"final", full}, {"indirect", indirect}, {"direct", direct}, {"emission", emission}};
}

}  // namespace

ParamSet pathTracerParams() {
    return ParamSet(
        {intParam("spp", 4, 1, 1 << 20, "",
                  "samples per pixel of one frame (each frame rendered from scratch)"),
         intParam("seed", 0, 0, 1000000000, "",
                  "sampling seed, added to the reference's seed + a fixed offset (repeats of one "
                  "spp give the baseline's seed spread)")},
        kPathTracerId);
}

ParamSet defaultRunParams(const std::string& id) {
    return id == kPathTracerId ? pathTracerParams()
                               : TechniqueRegistry::instance().defaultParams(id);
}

PtBaselineOutput renderPtBaseline(const Scene& scene, ref::ReferenceSettings settings, uint32_t spp,
                                  uint64_t seed, int warmup, int frames,
                                  const std::atomic<bool>* cancel) {
    if (spp == 0) throw Error("pathtracer: spp must be at least 1");
    if (frames < 1) throw Error("pathtracer: at least one timed frame is needed");
    settings.seed += kPathTracerSeedOffset + seed;
    settings.batchSamples = spp;  // one pass: the whole frame is one wavefront batch
    const auto setupStart = std::chrono::steady_clock::now();
    ref::PathTracer tracer(scene, settings);
    const double setupMs = msSince(setupStart);

    PtBaselineOutput out;
    std::vector<double> times;
    ref::Accumulator acc;
    for (int i = 0; i < warmup + frames; ++i) {
        acc.reset(scene.settings.width, scene.settings.height);
        const auto start = std::chrono::steady_clock::now();
        if (!tracer.addSamples(acc, spp, cancel)) throw Error("pathtracer: interrupted");
        const double ms = msSince(start);
        if (i < warmup) continue;
        times.push_back(ms);
        if (out.layers.empty()) out.layers = baselineLayers(acc);
    }
    const ref::RayStats& rays = tracer.stats();
    const double framesRun = double(warmup + frames);
    out.timing = {{"policy",
                   "docs/experiments.md \"The path-tracer baseline\": CPU wall clock of each "
                   "frame of spp samples per pixel rendered from scratch; warm-up discarded"},
                  {"setup_ms", {{"total", setupMs}}},
                  {"warmup_frames", warmup},
                  {"timed_frames", frames},
                  {"frame_cpu_ms", cli::summaryJson(times)}};
    out.stats = {{"spp", spp},
                 {"rays_per_frame", double(rays.totalRays()) / framesRun},
                 {"hardware_threads", std::thread::hardware_concurrency()},
                 {"non_finite_samples", acc.nonFiniteSamples}};
    return out;
}

}  // namespace gilab::exp
