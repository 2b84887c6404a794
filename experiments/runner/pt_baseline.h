#pragma once
/**
 * The equal-time path-tracer baseline (issue 44, docs/experiments.md "The path-tracer
 * baseline"): the reference renderer itself at a small sample count, timed on the CPU that runs
 * lavapipe, as a series of its own, technique id "pathtracer" with parameters `spp` and `seed`.
 * It calibrates what a lavapipe millisecond buys: at equal time, how close does plain path
 * tracing on the same two cores get? A "frame" renders `spp` samples per pixel from scratch;
 * set-up is the tracer's construction (BVH, light tables, textures).
 */
#include <atomic>
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/image/image.h"
#include "core/params/params.h"
#include "core/scene/scene.h"
#include "reference/reference_settings.h"

namespace gilab::exp {

inline constexpr const char* kPathTracerId = "pathtracer";
/** Added to the reference's seed, so the baseline's samples never repeat the reference's. */
inline constexpr uint64_t kPathTracerSeedOffset = 0x9e3779b97f4a7c15ull;

/** The baseline's parameters: `spp` (samples per pixel of a frame) and `seed`. */
ParamSet pathTracerParams();

/** The default parameters of technique `id`: pathTracerParams() for kPathTracerId, else the
 *  technique registry's (which throws for an unknown id). */
ParamSet defaultRunParams(const std::string& id);

struct PtBaselineOutput {
    /** "final" (full), "indirect" (full - emission - direct), "direct", "emission". */
    std::vector<ImageLayer> layers;
    nlohmann::ordered_json timing;  // setup_ms.total, frame_cpu_ms {median, q1, q3, iqr, ...}
    nlohmann::ordered_json stats;   // rays per frame, samples, threads
};

/**
 * Builds the tracer from `settings` (the reference's bounces, roulette, pixel filter) with the
 * seed settings.seed + kPathTracerSeedOffset + `seed`, then renders `warmup` untimed and
 * `frames` timed frames of `spp` samples per pixel; the layers are the first timed frame's.
 * Throws gilab::Error for spp == 0 or frames < 1.
 */
PtBaselineOutput renderPtBaseline(const Scene& scene, ref::ReferenceSettings settings, uint32_t spp,
                                  uint64_t seed, int warmup, int frames,
                                  const std::atomic<bool>* cancel = nullptr);

}  // namespace gilab::exp
