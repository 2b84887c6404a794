// `gilab bench reference`, per scene: timed render, ray replay, time to a relative MSE target.
#include "reference/bench.h"

#include <algorithm>
#include <cmath>

#include <tbb/task_arena.h>

#include "core/util/progress.h"
#include "reference/embree_scene.h"

namespace gilab::ref {
namespace {

/**
 * Expected relative MSE of a 1-sample image, from the per-pixel sample variance of `acc`:
 * E[(mean_n - mu)^2] = var / n, divided as relativeMse() divides (by mu^2 + 1e-2).
 */
double predictRelMseAtOneSample(const Accumulator& acc) {
    if (acc.samples < 2) return 0.0;
    double sum = 0.0;
    for (int y = 0; y < acc.height; ++y)
        for (int x = 0; x < acc.width; ++x)
            for (int c = 0; c < 3; ++c) {
                const double se = acc.stdError(Layer::Full, x, y, c);
                const double mu = acc.mean(Layer::Full, x, y, c);
                sum += se * se * double(acc.samples) / (mu * mu + 1e-2);
            }
    return sum / (3.0 * double(acc.width) * double(acc.height));
}

uint64_t roundUp(uint64_t n, uint64_t multiple) {
    return (n + multiple - 1) / multiple * multiple;
}

BenchConvergence measureConvergence(const Scene& scene, const ReferenceSettings& settings,
                                    PathTracer& tracer, const Accumulator& timed,
                                    const BenchOptions& o) {
    BenchConvergence conv;
    conv.targetRelMse = o.targetRelMse;
    const uint64_t batch = std::max<uint32_t>(settings.batchSamples, 1);
    // The timed render's few samples only size the long run: their per-pixel variance misses
    // rare bright paths (on the 256^2 Cornell glTF it predicted 260 spp where 1839 were needed)
    conv.sizingSamples = uint64_t(std::ceil(predictRelMseAtOneSample(timed) / o.targetRelMse));
    conv.longSamples = o.longSpp
                           ? o.longSpp
                           : std::clamp<uint64_t>(roundUp(8 * conv.sizingSamples, batch),
                                                  std::max<uint64_t>(64, batch), o.maxLongSpp);

    // 1. The long run, with another seed so that it is independent of the fresh run
    ReferenceSettings longSettings = settings;
    longSettings.seed = settings.seed + 0x9e3779b97f4a7c15ull;
    conv.longSeed = longSettings.seed;
    Image longImage;
    {
        PathTracer longTracer(scene, longSettings);
        Accumulator longAcc;
        longAcc.reset(scene.settings.width, scene.settings.height);
        const RenderReport report =
            renderUntil(longTracer, longAcc, StopCriteria{conv.longSamples, 0.0, o.maxLongSeconds});
        conv.longSamples = longAcc.samples;
        conv.longSeconds = report.seconds;
        // The prediction from the long run's variance (many more samples per pixel)
        conv.predictedSamples =
            uint64_t(std::ceil(predictRelMseAtOneSample(longAcc) / o.targetRelMse));
        longImage = meanImage(longAcc, Layer::Full);
    }

    // 2. A fresh run, checked against it after every batch until it first drops below target
    Accumulator fresh;
    fresh.reset(scene.settings.width, scene.settings.height);
    const uint64_t limit = std::max(conv.longSamples / 2, batch);
    Progress progress("convergence on " + scene.name);
    double seconds = 0.0;
    while (true) {
        Stopwatch watch;
        tracer.addSamples(fresh, uint32_t(batch));
        seconds += watch.elapsedMs() * 1e-3;
        const double mse = relativeMse(meanImage(fresh, Layer::Full), longImage);
        conv.curve.push_back({fresh.samples, seconds, meanRelativeStdError(fresh), mse});
        char detail[96];
        std::snprintf(detail, sizeof detail, "%llu spp, rel MSE %.3g",
                      (unsigned long long)fresh.samples, mse);
        progress.update(0, detail);
        if (mse < o.targetRelMse) {
            conv.reached = true;
            conv.samples = fresh.samples;
            conv.seconds = seconds;
            break;
        }
        if (fresh.samples >= limit || seconds > o.maxLongSeconds) break;
    }
    progress.finish();

    const ConvergencePoint& last = conv.curve.back();
    if (last.samples > 0 && std::isfinite(last.relMseVsLong)) {
        const double a =
            last.relMseVsLong / (1.0 / double(last.samples) + 1.0 / double(conv.longSamples));
        conv.extrapolatedSamples = uint64_t(std::ceil(a / o.targetRelMse));
        conv.extrapolatedSeconds =
            double(conv.extrapolatedSamples) * last.seconds / double(last.samples);
    }
    return conv;
}

/** The fastest raw Embree method's rate for the render's ray mix (all threads). */
double bestRawMix(const BenchSceneResult& r) {
    double best = 0.0;
    for (const char* method : {"1", "8", "16", "1M"})
        best = std::max(best, r.rawMixRaysPerSecond(method, r.threads));
    return best;
}

nlohmann::ordered_json rateJson(const ReplayRate& r) {
    return {{"method", r.method},
            {"threads", r.threads},
            {"rays", r.rays},
            {"seconds", r.seconds},
            {"rays_per_second", r.raysPerSecond()},
            {"hits_per_pass", r.hitsPerPass}};
}

const ReplayRate* findRate(const std::vector<ReplayRate>& rates, const std::string& prefix,
                           int threads) {
    for (const ReplayRate& r : rates)
        if (r.threads == threads && r.method.size() >= prefix.size() &&
            r.method.compare(r.method.size() - prefix.size(), prefix.size(), prefix) == 0)
            return &r;
    return nullptr;
}

}  // namespace

double BenchSceneResult::closestRaysPerSecond() const {
    return rays.seconds > 0.0 ? double(rays.cameraRays + rays.bounceRays) / rays.seconds : 0.0;
}

double BenchSceneResult::shadowRaysPerSecond() const {
    return rays.seconds > 0.0 ? double(rays.shadowRays) / rays.seconds : 0.0;
}

double BenchSceneResult::raysPerSecond() const {
    return rays.seconds > 0.0 ? double(rays.totalRays()) / rays.seconds : 0.0;
}

double BenchSceneResult::rawMixRaysPerSecond(const std::string& method, int threadCount) const {
    // method is the suffix after "rtcIntersect"/"rtcOccluded": "1", "8", "16", "1M"
    const ReplayRate* closest = findRate(replay.closest, method, threadCount);
    const ReplayRate* shadow = findRate(replay.shadow, method, threadCount);
    const double closestRays = double(rays.cameraRays + rays.bounceRays);
    const double shadowRays = double(rays.shadowRays);
    double seconds = 0.0;
    if (closestRays > 0.0) {
        if (!closest || closest->raysPerSecond() <= 0.0) return 0.0;
        seconds += closestRays / closest->raysPerSecond();
    }
    if (shadowRays > 0.0) {
        if (!shadow || shadow->raysPerSecond() <= 0.0) return 0.0;
        seconds += shadowRays / shadow->raysPerSecond();
    }
    return seconds > 0.0 ? (closestRays + shadowRays) / seconds : 0.0;
}

BenchSceneResult benchReferenceScene(const Scene& scene, const ReferenceSettings& settings,
                                     const BenchOptions& options) {
    BenchSceneResult res;
    res.scene = scene.name;
    res.width = scene.settings.width;
    res.height = scene.settings.height;
    res.triangles = scene.triangleCount();
    res.threads = tbb::this_task_arena::max_concurrency();

    // 1. Timed render (all threads)
    PathTracer tracer(scene, settings);
    res.tracer = tracer.toString();
    res.alphaFilter = tracer.embree().hasAlphaFilter();
    Accumulator acc;
    acc.reset(res.width, res.height);
    const RenderReport report = renderUntil(tracer, acc, StopCriteria{options.spp, 0.0, 0.0});
    res.spp = acc.samples;
    res.rays = report.rays;

    // 2. Record the rays of a short single-threaded render, replay them against raw Embree
    {
        std::vector<RecordedRay> rays;
        Accumulator recorded;
        recorded.reset(res.width, res.height);
        tracer.recordRays(&rays);
        tbb::task_arena oneThread(1);
        oneThread.execute([&] { tracer.addSamples(recorded, options.recordSamples); });
        tracer.recordRays(nullptr);
        Progress progress("replaying " + std::to_string(rays.size()) + " rays on " + scene.name);
        res.replay =
            replayRays(tracer.embree().handle(), rays, res.threads, options.minReplaySeconds);
        progress.finish();
    }

    // 3. Samples and seconds to a relative MSE target against a long run
    res.convergence = measureConvergence(scene, settings, tracer, acc, options);
    return res;
}

nlohmann::ordered_json benchSceneJson(const BenchSceneResult& r) {
    nlohmann::ordered_json closest = nlohmann::ordered_json::array();
    nlohmann::ordered_json shadow = nlohmann::ordered_json::array();
    for (const ReplayRate& rate : r.replay.closest)
        closest.push_back(rateJson(rate));
    for (const ReplayRate& rate : r.replay.shadow)
        shadow.push_back(rateJson(rate));
    nlohmann::ordered_json curve = nlohmann::ordered_json::array();
    for (const ConvergencePoint& p : r.convergence.curve)
        curve.push_back({p.samples, p.seconds, p.relError, p.relMseVsLong});
    const BenchConvergence& c = r.convergence;
    return {{"scene", r.scene},
            {"resolution", {r.width, r.height}},
            {"triangles", r.triangles},
            {"threads", r.threads},
            {"tracer", r.tracer},
            {"alpha_filter", r.alphaFilter},
            {"path_tracer",
             {{"spp", r.spp},
              {"seconds", r.rays.seconds},
              {"camera_rays", r.rays.cameraRays},
              {"bounce_rays", r.rays.bounceRays},
              {"shadow_rays", r.rays.shadowRays},
              {"closest_rays_per_second", r.closestRaysPerSecond()},
              {"shadow_rays_per_second", r.shadowRaysPerSecond()},
              {"rays_per_second", r.raysPerSecond()}}},
            {"raw_embree",
             {{"recorded_closest_rays", r.replay.closestRays},
              {"recorded_shadow_rays", r.replay.shadowRays},
              {"closest", closest},
              {"shadow", shadow},
              {"mix_rays_per_second_1_mt", r.rawMixRaysPerSecond("1", r.threads)},
              {"path_tracer_over_raw_1_mt",
               r.rawMixRaysPerSecond("1", r.threads) > 0.0
                   ? r.raysPerSecond() / r.rawMixRaysPerSecond("1", r.threads)
                   : 0.0},
              {"best_raw_mix_rays_per_second_mt", bestRawMix(r)},
              {"path_tracer_over_best_raw_mt",
               bestRawMix(r) > 0.0 ? r.raysPerSecond() / bestRawMix(r) : 0.0},
              {"warnings", r.replay.warnings}}},
            {"convergence",
             {{"target_rel_mse", c.targetRelMse},
              {"predicted_samples", c.predictedSamples},
              {"sizing_samples", c.sizingSamples},
              {"long_samples", c.longSamples},
              {"long_seconds", c.longSeconds},
              {"long_seed", c.longSeed},
              {"reached", c.reached},
              {"samples", c.samples},
              {"seconds", c.seconds},
              {"extrapolated_samples", c.extrapolatedSamples},
              {"extrapolated_seconds", c.extrapolatedSeconds},
              {"seconds_per_sample", c.secondsPerSample()},
              {"efficiency", c.efficiency()},
              {"curve_columns", {"samples", "seconds", "rel_error", "rel_mse_vs_long"}},
              {"curve", curve}}}};
}

}  // namespace gilab::ref
