#pragma once
/**
 * `gilab bench reference` (docs/reference_cache.md, "Benchmark"): the path tracer's ray rates,
 * the same rays replayed against raw Embree (rtcIntersect1/rtcOccluded1, 8- and 16-wide
 * packets, 1M streams; one thread and all threads), and the samples and seconds needed to reach
 * a relative MSE of 1e-3 against a long run. A command that prints figures, not a timed test.
 */
#include <string>
#include <vector>

#include <embree3/rtcore.h>
#include <nlohmann/json.hpp>

#include "core/scene/scene.h"
#include "reference/path_tracer.h"

namespace gilab::ref {

/** Replay rate of one Embree entry point at one thread count, for one kind of ray. */
struct ReplayRate {
    std::string method;  // "rtcIntersect1", "rtcIntersect8", "rtcIntersect16", "rtcIntersect1M"
    int threads = 1;
    uint64_t rays = 0;  // rays traced (passes x recorded rays)
    double seconds = 0.0;
    uint64_t hitsPerPass = 0;  // hits (closest) or occluded rays (shadow): equal across methods
    double raysPerSecond() const { return seconds > 0.0 ? double(rays) / seconds : 0.0; }
};

struct ReplayResult {
    uint64_t closestRays = 0;  // recorded camera + bounce rays
    uint64_t shadowRays = 0;
    std::vector<ReplayRate> closest;    // rtcIntersect*
    std::vector<ReplayRate> shadow;     // rtcOccluded*
    std::vector<std::string> warnings;  // methods that disagree on the hit count
};

/**
 * Traces `rays` against `scene` with every method, single-threaded and on `threads` TBB
 * threads, repeating each until `minSeconds` have passed. Methods that disagree on the hit count
 * (they trace the same rays) are listed in `warnings`.
 */
ReplayResult replayRays(RTCScene scene, const std::vector<RecordedRay>& rays, int threads,
                        double minSeconds);

struct BenchOptions {
    uint64_t spp = 16;           // timed render
    uint32_t recordSamples = 1;  // samples per pixel recorded for the replay
    double minReplaySeconds = 0.3;
    double targetRelMse = 1e-3;
    uint64_t longSpp = 0;           // 0 = 8 x the predicted samples needed, within the caps
    uint64_t maxLongSpp = 65536;    // caps of the automatic long run
    double maxLongSeconds = 120.0;  // time cap of the long run and of the fresh run
};

struct BenchConvergence {
    double targetRelMse = 0.0;
    uint64_t predictedSamples = 0;  // from the long run's per-pixel variance
    uint64_t sizingSamples = 0;     // from the timed render's (sizes the long run only)
    uint64_t longSamples = 0;
    double longSeconds = 0.0;
    uint64_t longSeed = 0;
    bool reached = false;
    uint64_t samples = 0;  // first batch whose relative MSE vs the long run is below target
    double seconds = 0.0;  // render time (addSamples only) to get there
    /** From the last curve point, with the long run's own noise removed (relative MSE ~ a / n
     *  against the exact image, a / n + a / longSamples against the long run). */
    uint64_t extrapolatedSamples = 0;
    double extrapolatedSeconds = 0.0;
    std::vector<ConvergencePoint> curve;

    /** Render seconds per sample per pixel at the last curve point. */
    double secondsPerSample() const {
        return curve.empty() || curve.back().samples == 0
                   ? 0.0
                   : curve.back().seconds / double(curve.back().samples);
    }
    /** 1 / (relative MSE x seconds), independent of the sample count: the target over the
     *  extrapolated seconds to reach it. */
    double efficiency() const {
        return extrapolatedSeconds > 0.0 ? 1.0 / (targetRelMse * extrapolatedSeconds) : 0.0;
    }
};

struct BenchSceneResult {
    std::string scene;
    int width = 0;
    int height = 0;
    size_t triangles = 0;
    int threads = 0;
    std::string tracer;  // PathTracer::toString()
    bool alphaFilter = false;
    uint64_t spp = 0;
    RayStats rays;  // of the timed render
    ReplayResult replay;
    BenchConvergence convergence;

    double closestRaysPerSecond() const;  // (camera + bounce) / render seconds
    double shadowRaysPerSecond() const;   // shadow / render seconds
    double raysPerSecond() const;         // all / render seconds
    /** Raw Embree rate for the timed render's mix of closest-hit and shadow rays. */
    double rawMixRaysPerSecond(const std::string& method, int threads) const;
};

/** Timed render, ray replay and convergence for one scene; progress lines on stderr. */
BenchSceneResult benchReferenceScene(const Scene& scene, const ReferenceSettings& settings,
                                     const BenchOptions& options);

nlohmann::ordered_json benchSceneJson(const BenchSceneResult& result);

}  // namespace gilab::ref
