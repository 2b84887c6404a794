#pragma once
/**
 * Experiment configs (JSON, docs/experiments.md): scenes x techniques x parameter sweeps, the
 * reference settings, the timing policy and the metric options. Everything is validated when the
 * file is read — unknown keys, unknown techniques, out-of-range parameters and malformed sweeps
 * are errors naming the file and the key path — before any run starts.
 */
#include <algorithm>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/image/image_io.h"
#include "core/params/params.h"
#include "reference/reference_settings.h"

namespace gilab::exp {

struct SceneEntry {
    std::string
        path;  // scene description, relative paths resolved against the config; "" = built-in
    std::string variant;  // "" = the file's base setup
    int width = 0;        // 0 = the scene's own resolution
    int height = 0;
    std::string label;  // e.g. "cornell_box#spot"; unique within the experiment
};

struct ReferenceRequest {
    ref::ReferenceSettings settings;
    ref::StopCriteria stop;
    /** Animated scenes: the reference (and the per-frame metrics) cover every frameStep-th
     *  frame, starting at 0 ("frames": "all" = 1, or an integer k). */
    int frameStep = 1;
};

struct TimingPolicy {
    int warmupFrames = 2;
    int timedFrames = 5;
    // More frames while the frame GPU time's interquartile range is above targetIqr x its median
    // (lavapipe is noisy), up to maxFrames in all; a run that stops above it is flagged noisy.
    double targetIqr = 0.10;
    int maxFrames = 0;  // 0: 4 x timedFrames (at least 20)
    int frameLimit() const { return maxFrames > 0 ? maxFrames : std::max(4 * timedFrames, 20); }
};

/** A named region for metrics: a rectangle (normalised 0..1) or an indirect-light mask. */
struct RegionSpec {
    std::string name;
    std::optional<std::array<double, 4>> rect;  // x0, y0, x1, y1 in [0, 1]
    double indirectFractionAbove = -1.0;        // > 0: pixels whose reference indirect > x * total
};

struct MetricOptionsSpec {
    double ppd = 67.0;
    float exposureEv = 0.0f;  // LDR metrics and previews; added to the scene's exposure
    std::vector<RegionSpec> regions;
    /** VPL techniques: shade their VPLs with exact shadow rays too (experiments/runner/
     *  same_vpl.h, the Table II reference of Noël & Biri 2014). */
    bool sameVplReference = false;
};

/** One technique block: fixed parameters plus sweeps (grid = cartesian, zip = lock-step). */
struct TechniqueEntry {
    std::string id;
    std::map<std::string, nlohmann::json> fixed;
    std::vector<std::pair<std::string, std::vector<nlohmann::json>>> grid;
    std::vector<std::pair<std::string, std::vector<nlohmann::json>>> zip;
    std::map<std::string, nlohmann::json> shared;  // shared-pass overrides for this technique
    std::vector<std::string> scenes;  // scene labels this block runs on; empty = every scene
    /** "repeats": each run this many times; repeats 1..n-1 come after every block's first
     *  round (interleaved with the other techniques' runs), for the between-run timing spread
     *  (docs/experiments.md, "Repeats"). */
    int repeats = 1;
    /** "frames": timed frames of this block's runs (0 = the config's "timing.frames"). */
    int timedFrames = 0;
    /** "warmup": warm-up frames of this block's runs (-1 = the config's "timing.warmup"), e.g.
     *  the updates a probe technique needs to converge before scoring. */
    int warmupFrames = -1;
};

/** Default of "max_runs": a config whose sweeps expand to more runs is refused. */
inline constexpr size_t kDefaultMaxRuns = 100000;
/** The largest "max_runs" a config may set (planning costs memory per run). */
inline constexpr int kMaxRunsCeiling = 100000000;
/** What one planned run is taken to cost in memory (checkRunCount refuses a plan that would
 *  need more than a quarter of the machine's memory). */
inline constexpr size_t kPlanningBytesPerRun = 16 * 1024;
/** A quarter of the machine's physical memory: what planning may use. */
size_t planningMemoryBudget();

struct ExperimentConfig {
    std::string name;
    std::string path;
    std::string description;
    std::vector<SceneEntry> scenes;
    ReferenceRequest reference;
    TimingPolicy timing;
    MetricOptionsSpec metrics;
    std::map<std::string, nlohmann::json> shared;  // shared-pass parameters for every run
    std::vector<TechniqueEntry> techniques;
    size_t maxRuns = kDefaultMaxRuns;  // "max_runs"
};

ExperimentConfig loadExperimentConfig(const std::string& path);
/** Parses from memory; `context` (e.g. the path) prefixes every message. */
ExperimentConfig parseExperimentConfig(const nlohmann::json& json, const std::string& context,
                                       const std::string& baseDir);

/** One run: a scene, a technique and one point of its sweep. */
struct RunSpec {
    size_t index = 0;  // position in the expanded list (stable for a given config)
    const SceneEntry* scene = nullptr;
    std::string techniqueId;
    ParamSet params;
    ParamSet shared;
    std::map<std::string, std::string> swept;  // swept key -> canonical value text
    int repeat = 0;         // 0 = the first run of this configuration; r > 0: its r-th repeat
    int timedFrames = 0;    // timed frames (0 = the config's)
    int warmupFrames = -1;  // warm-up frames (-1 = the config's)
};

/** Expands every technique block into runs (scenes outermost), validating every value.
 *  Throws (checkRunCount) before expanding anything if there would be more than maxRuns. */
std::vector<RunSpec> expandRuns(const ExperimentConfig& config);

/** The number of runs expandRuns would make, without expanding (capped at `saturateAt`). */
size_t countRuns(const ExperimentConfig& config, size_t saturateAt);
/** Throws gilab::Error naming the count and "max_runs" if the sweeps exceed config.maxRuns,
 *  or the memory their plan needs if it exceeds planningMemoryBudget(). */
void checkRunCount(const ExperimentConfig& config);

/** The metric options as JSON (part of every run's identity). */
nlohmann::ordered_json metricsSpecJson(const MetricOptionsSpec& spec);

/** Values of a range object {"linear": [from, to, count]} or {"log": [from, to, count]}. */
std::vector<nlohmann::json> expandRange(const nlohmann::json& range, bool integer,
                                        const std::string& where);

}  // namespace gilab::exp
