#include "experiments/runner/runner.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <set>

#include "core/image/image_io.h"
#include "core/passes/shared_passes.h"
#include "core/scene/animation.h"
#include "core/scene/scene_loader.h"
#include "core/technique/frame_harness.h"
#include "core/technique/registry.h"
#include "core/util/build_info.h"
#include "core/util/error.h"
#include "core/util/hash.h"
#include "core/util/json_reader.h"
#include "core/util/progress.h"
#include "core/vk/context.h"
#include "experiments/runner/dry_run.h"
#include "experiments/runner/experiment_config.h"
#include "experiments/runner/pt_baseline.h"
#include "experiments/runner/reference_set.h"
#include "experiments/runner/run_metadata.h"
#include "experiments/runner/run_metrics.h"
#include "experiments/runner/run_sequence.h"
#include "experiments/runner/run_store.h"
#include "experiments/runner/same_vpl.h"
#include "experiments/runner/timing_probe.h"
#include "reference/scene_hash.h"

namespace gilab::exp {
namespace fs = std::filesystem;

namespace {

/** Bumped when the meaning of a run's result changes, so finished runs are redone. */
constexpr int kRunFormatVersion = 2;  // 2: metrics.final_vs_bounces (metrics.direct is additive)

/** Loads each scene of the experiment once, applying the config's resolution. */
class SceneCache {
public:
    const Scene& get(const SceneEntry& entry) {
        auto it = m_scenes.find(entry.label);
        if (it != m_scenes.end()) return *it->second;
        auto scene = std::make_unique<Scene>(entry.variant.empty()
                                                 ? loadScene(entry.path)
                                                 : loadSceneFile(entry.path, entry.variant));
        if (entry.width > 0) {
            scene->settings.width = entry.width;
            scene->settings.height = entry.height;
        }
        for (const std::string& w : scene->warnings)
            std::fprintf(stderr, "gilab: %s: warning: %s\n", entry.label.c_str(), w.c_str());
        return *m_scenes.emplace(entry.label, std::move(scene)).first->second;
    }

private:
    std::map<std::string, std::unique_ptr<Scene>> m_scenes;
};

/**
 * The technique parameters of a run's key: all of them, except a parameter added after results
 * existed while it has the value that reproduces the images from before it (`seed` = 0: the
 * techniques' sampling patterns, docs/experiments.md), so finished runs keep their keys.
 */
nlohmann::ordered_json keyParams(const ParamSet& params) {
    nlohmann::ordered_json p = params.toOrderedJson();
    if (p.contains("seed") && p["seed"] == 0) p.erase("seed");
    return p;
}

/** Everything that changes a static run's result. */
nlohmann::ordered_json runIdentityStatic(const ExperimentConfig& config, const RunSpec& run,
                                         const Scene& scene) {
    return {{"run_format", kRunFormatVersion},
            {"scene_label", run.scene->label},
            {"reference_key", ref::referenceKey(scene, config.reference.settings)},
            {"reference_stop", ref::stopCriteriaJson(config.reference.stop)},
            {"technique", run.techniqueId},
            {"params", keyParams(run.params)},
            {"shared", run.shared.toOrderedJson()},
            {"warmup", run.warmupFrames >= 0 ? run.warmupFrames : config.timing.warmupFrames},
            {"frames", run.timedFrames > 0 ? run.timedFrames : config.timing.timedFrames},
            {"metrics", metricsSpecJson(config.metrics)}};
}

/** A repeat's identity: the first run's plus its index (the first run keeps its key). */
nlohmann::ordered_json withRepeat(nlohmann::ordered_json id, const RunSpec& run) {
    if (run.repeat > 0) id["repeat"] = run.repeat;
    return id;
}

/** What an animation moves: "light" (a track on a light), "camera" (on the camera). */
nlohmann::ordered_json animationMoves(const Scene& scene) {
    std::set<std::string> moves;
    for (const AnimationTrack& track : scene.animation.tracks) {
        const std::string target = animationTarget(track);
        moves.insert(target.rfind("light", 0) == 0    ? "light"
                     : target.rfind("camera", 0) == 0 ? "camera"
                                                      : "other");
    }
    return nlohmann::ordered_json(std::vector<std::string>(moves.begin(), moves.end()));
}

/** The scene at frame `frame` of its animation (lights and camera moved; same geometry). */
Scene sceneAtFrame(const Scene& scene, int frame) {
    Scene s = scene;
    applyFrameState(s, frameState(scene, frame));
    return s;
}

/** Animated scenes: the reference keys of the measured frames (they change with any track). */
nlohmann::ordered_json sequenceIdentity(const ExperimentConfig& config, const Scene& scene) {
    if (!scene.animation.animated()) return nullptr;
    nlohmann::ordered_json keys = nlohmann::ordered_json::array();
    for (int f : measuredFrames(scene.animation.frameCount, config.reference.frameStep))
        keys.push_back(ref::referenceKey(sceneAtFrame(scene, f), config.reference.settings));
    return {{"frames", scene.animation.frameCount},
            {"duration_s", scene.animation.duration},
            {"frame_step", config.reference.frameStep},
            {"reference_keys", keys}};
}

/** Everything that changes a run's result, hashed: the run key. Static scenes keep the keys
 *  they had before animation existed. */
nlohmann::ordered_json runIdentity(const ExperimentConfig& config, const RunSpec& run,
                                   const Scene& scene) {
    nlohmann::ordered_json id = withRepeat(runIdentityStatic(config, run, scene), run);
    nlohmann::ordered_json sequence = sequenceIdentity(config, scene);
    if (!sequence.is_null()) id["sequence"] = std::move(sequence);
    return id;
}

struct Context {
    const ExperimentConfig& config;
    const RunnerOptions& options;
    RunStore& store;
    vk::Context& vk;
    ref::ReferenceCache* cache;
    SceneCache scenes;
    std::map<std::string, std::unique_ptr<ReferenceSet>> references;
    std::map<std::string, bool> writtenReferencePreviews;
    const std::atomic<bool>* cancel;
    std::string configHash;
};

/** SIGINT or SIGTERM during a reference: the partial reference is cached, the run is dropped
 *  (not committed) and the experiment stops like at a run boundary. */
struct ReferenceInterrupted {};

/** "<label>" or "<label>@<frame>": how a reference is named in logs and --references-only. */
std::string referenceId(const SceneEntry& entry, int frame) {
    return frame < 0 ? entry.label : entry.label + "@" + std::to_string(frame);
}

/**
 * The complete reference of `scene` from the cache, rendered (or continued) if needed. Under
 * the cache's lock for its key, so processes sharing the cache render it once (the others wait
 * and reuse it). One log line says which: "rendered reference KEY" or "reused reference KEY".
 */
ref::ReferenceResult obtainSceneReference(const ExperimentConfig& config,
                                          const RunnerOptions& options, ref::ReferenceCache* cache,
                                          const std::atomic<bool>* cancel, const Scene& scene,
                                          const std::string& id) {
    ref::ObtainOptions opts;
    opts.cancel = cancel;
    opts.sidecarExtra["scene"] = cli::sceneToJson(scene);
    opts.sidecarExtra["provenance"] = cli::provenanceJson(options.commandLine);
    std::fprintf(stderr, "[gilab] reference for %s\n", id.c_str());
    ref::ReferenceResult r =
        ref::obtainReference(scene, config.reference.settings, config.reference.stop, cache, opts);
    for (const std::string& w : r.warnings)
        std::fprintf(stderr, "gilab: warning: %s\n", w.c_str());
    if (r.reason == ref::StopReason::Cancelled) throw ReferenceInterrupted{};  // partial: cached
    if (!r.complete)
        throw Error("reference for " + id + " was interrupted (" + ref::stopReasonName(r.reason) +
                    "); runs need a complete reference");
    if (r.renderedSamples > 0)
        std::fprintf(stderr, "[gilab] rendered reference %s for %s: %llu samples in %.1f s\n",
                     r.key.c_str(), id.c_str(), (unsigned long long)r.renderedSamples,
                     r.report.seconds);
    else
        std::fprintf(stderr, "[gilab] reused reference %s for %s (%llu samples)\n", r.key.c_str(),
                     id.c_str(), (unsigned long long)r.acc.samples);
    return r;
}

/** The reference of `scene` (frame `frame` of an animated entry; -1 = the static scene). */
const ReferenceSet& referenceFor(Context& c, const SceneEntry& entry, const Scene& scene,
                                 int frame = -1) {
    const std::string id = referenceId(entry, frame);
    auto it = c.references.find(id);
    if (it != c.references.end()) return *it->second;
    ref::ReferenceResult r =
        obtainSceneReference(c.config, c.options, c.cache, c.cancel, scene, id);
    return *c.references.emplace(id, std::make_unique<ReferenceSet>(std::move(r))).first->second;
}

/** One reference the runs of a config compare with. */
struct ReferenceTask {
    const SceneEntry* entry;
    int frame;  // -1: the static scene
};

/** The distinct references of `runs` (by cache key): each scene entry's, then its animation
 *  frames' (frame 0 of an animation is usually the static scene's key, listed once). */
std::vector<ReferenceTask> referenceTasks(const ExperimentConfig& config,
                                          const std::vector<RunSpec>& runs, SceneCache& scenes) {
    std::vector<ReferenceTask> tasks;
    std::set<std::string> labels, keys;
    auto add = [&](const SceneEntry* entry, int frame, const Scene& scene) {
        if (keys.insert(ref::referenceKey(scene, config.reference.settings)).second)
            tasks.push_back({entry, frame});
    };
    for (const RunSpec& r : runs) {
        if (!labels.insert(r.scene->label).second) continue;
        const Scene& scene = scenes.get(*r.scene);
        add(r.scene, -1, scene);
        if (scene.animation.animated())
            for (int f : measuredFrames(scene.animation.frameCount, config.reference.frameStep))
                add(r.scene, f, sceneAtFrame(scene, f));
    }
    return tasks;
}

/**
 * Writes `path` through a temporary file beside it (same extension, so the image writers pick
 * the format) and one rename, so processes sharing the results folder never see a half-written
 * file, even when two write the same one.
 */
void writeAtomically(const fs::path& path, const std::function<void(const std::string&)>& write) {
    const fs::path tmp =
        path.parent_path() / (".tmp-" + processTag() + "-" + path.filename().string());
    write(tmp.string());
    fs::rename(tmp, path);
}

/**
 * references/<label>/: the matched reference <matched>.{exr,png}, the full reference
 * full.{exr,png}, and the indirect light the run's `indirect` layer is compared with,
 * indirect_<bounces>.png (e.g. indirect_bounce1.png; indirect_full.png = all indirect light).
 * Each file is written once per experiment folder. Returns the paths relative to a run folder.
 */
nlohmann::ordered_json writeReferencePreview(Context& c, const SceneEntry& entry,
                                             const MatchedReference& m, const ToneMap& tm) {
    const std::string safeLabel = sanitizeLabel(entry.label);
    const fs::path dir = c.store.dir() / "references" / safeLabel;
    const std::string rel = "../../references/" + safeLabel + "/";
    auto once = [&](const std::string& file, const auto& write) {
        const std::string id = safeLabel + "/" + file;
        if (c.writtenReferencePreviews[id]) return;
        fs::create_directories(dir);
        writeAtomically(dir / file, write);
        c.writtenReferencePreviews[id] = true;
    };
    auto exr = [&](const std::string& file, const Image& mean, const Image& stdError) {
        once(file, [&](const std::string& path) {
            writeExrWithMainImage(
                path, {{"final", mean}, {"final_stderr", stdError}}, "final",
                {{kPixelFilterAttribute,
                  ref::pixelFilterName(c.config.reference.settings.pixelFilter)}});
        });
    };
    auto png = [&](const std::string& file, const Image& image) {
        once(file, [&](const std::string& path) { writePngTonemapped(path, image, tm); });
    };
    exr(m.name + ".exr", m.final, m.finalStdError);
    png(m.name + ".png", m.final);
    exr("full.exr", m.full, m.fullStdError);
    png("full.png", m.full);
    png("indirect_full.png", m.fullIndirect);
    nlohmann::ordered_json out = {{"final_png", rel + m.name + ".png"},
                                  {"final_exr", rel + m.name + ".exr"},
                                  {"full_png", rel + "full.png"},
                                  {"full_exr", rel + "full.exr"},
                                  {"indirect_full_png", rel + "indirect_full.png"}};
    if (!m.indirect.empty()) {
        const std::string prefix = "emission+direct+";
        const std::string bounces =
            m.name.rfind(prefix, 0) == 0 ? m.name.substr(prefix.size()) : m.name;
        png("indirect_" + bounces + ".png", m.indirect);
        out["indirect_png"] = rel + "indirect_" + bounces + ".png";
    }
    return out;
}

std::string framePreviewName(int frame) {
    char name[32];
    std::snprintf(name, sizeof name, "%03d_full.png", frame);
    return name;
}

/** references/<label>/frames/NNN_full.png: the full reference of an animation frame. */
void writeReferenceFramePreview(Context& c, const SceneEntry& entry, int frame,
                                const ReferenceSet& set, const ToneMap& tm) {
    const std::string safeLabel = sanitizeLabel(entry.label);
    const std::string id = safeLabel + "/frames/" + framePreviewName(frame);
    if (c.writtenReferencePreviews[id]) return;
    const fs::path dir = c.store.dir() / "references" / safeLabel / "frames";
    fs::create_directories(dir);
    writeAtomically(dir / framePreviewName(frame), [&](const std::string& path) {
        writePngTonemapped(path, set.match(kAllBounces).full, tm);
    });
    c.writtenReferencePreviews[id] = true;
}

/** Prints where the messages of an invalid run are (the first ones went to stderr already). */
void reportInvalid(const nlohmann::ordered_json& result, const fs::path& runDir) {
    const auto& v = result["validation"];
    std::fprintf(stderr,
                 "gilab: run %zu (%s on %s) is invalid: %u Vulkan validation errors and %u "
                 "warnings (messages in %s)\n",
                 result["index"].get<size_t>(),
                 result["technique"]["id"].get<std::string>().c_str(),
                 result["scene"]["label"].get<std::string>().c_str(), v["errors"].get<uint32_t>(),
                 v["warnings"].get<uint32_t>(), (runDir / "result.json").string().c_str());
}

/** One line per finished run on stdout, also when it is not a terminal (batch logs). */
void printRunLine(const nlohmann::ordered_json& row, bool quiet) {
    if (quiet) return;
    auto number = [&](const char* key) {
        return row.contains(key) && row[key].is_number() ? row[key].get<double>() : -1.0;
    };
    std::string line = "run " + std::to_string(row.value("index", 0)) + " " +
                       row.value("technique", "") + " on " + row.value("scene", "") + ": " +
                       row.value("status", "");
    char buf[160];
    if (number("sequence.full.flip_mean") >= 0.0) {  // animated: the sequence, dynamic frames
        std::snprintf(buf, sizeof buf,
                      ", HDR-FLIP vs full %.3f (mean over the measured frames), temporal "
                      "instability %.3f, dynamic frame %.2f ms (%s update)",
                      number("sequence.full.flip_mean"), number("sequence.temporal.instability"),
                      number("dynamic_frame_gpu_ms_median"), row.value("update_kind", "").c_str());
        line += buf;
    } else if (number("full.flip") >= 0.0) {
        std::snprintf(buf, sizeof buf, ", HDR-FLIP vs full %.3f, relMSE vs full %.4f",
                      number("full.flip"), number("full.rel_mse"));
        line += buf;
    }
    if (row.value("technique", "") == kPathTracerId && number("frame_cpu_ms_median") >= 0.0) {
        std::snprintf(buf, sizeof buf, ", frame %.2f ms (CPU path tracer)",
                      number("frame_cpu_ms_median"));
        line += buf;
    }
    if (number("frame_gpu_ms_median") >= 0.0) {
        std::snprintf(buf, sizeof buf, ", %s %.2f ms (%s)",
                      number("sequence.full.flip_mean") >= 0.0 ? "static frame" : "frame",
                      number("frame_gpu_ms_median"),
                      row.value("device_type", "") == "cpu" ? "lavapipe, CPU" : "GPU");
        line += buf;
    }
    const std::string params = row.value("params", "");
    std::printf("%s%s%s\n", line.c_str(), params.empty() ? "" : "  ", params.c_str());
    std::fflush(stdout);
}

/**
 * Adds the run's validation messages and final status to `result`, writes result.json, commits
 * the run folder and appends its row. Returns the status.
 */
std::string commitResult(Context& c, nlohmann::ordered_json& result, const fs::path& tmp,
                         const std::string& key, RunOutcome outcome) {
    result["validation"] = cli::takeValidationJson(c.vk);
    outcome.validationMessages = cli::validationMessageCount(result["validation"]);
    result["status"] = runStatus(outcome);
    writeFileAtomic(tmp / "result.json", result.dump(2));
    c.store.commitRun(tmp, key);
    const nlohmann::ordered_json row = resultRow(result);
    c.store.appendRow(row);
    if (result["status"] == "invalid") reportInvalid(result, c.store.runDir(key));
    printRunLine(row, c.options.quiet);
    return result["status"];
}

/** Executes one run into a temporary folder and commits it. Returns its status. */
/** The run's identity block of result.json (shared by techniques and the path tracer). */
void beginResult(Context& c, nlohmann::ordered_json& result, const RunSpec& run,
                 const std::string& key, const Scene& scene) {
    result["schema"] = 1;
    result["status"] = "running";
    result["key"] = key;
    result["index"] = run.index;
    result["repeat"] = run.repeat;
    result["experiment"] = c.config.name;
    result["scene"] = {{"label", run.scene->label},
                       {"path", run.scene->path},
                       {"variant", run.scene->variant},
                       {"resolution", {scene.settings.width, scene.settings.height}}};
}

/** The tone map of a run's previews and LDR metrics: the scene's exposure plus the config's. */
ToneMap runToneMap(const Context& c, const Scene& scene) {
    ToneMap tm;
    tm.exposureEv = scene.settings.exposureEv + c.config.metrics.exposureEv;
    return tm;
}

/** The run's timed frames: its block's "frames", else the config's. */
int timedFrames(const Context& c, const RunSpec& run) {
    return run.timedFrames > 0 ? run.timedFrames : c.config.timing.timedFrames;
}

int warmupFrames(const Context& c, const RunSpec& run) {
    return run.warmupFrames >= 0 ? run.warmupFrames : c.config.timing.warmupFrames;
}

/** result["reference"]: the reference the run is compared with, and its preview. */
void addReferenceBlock(Context& c, nlohmann::ordered_json& result, const RunSpec& run,
                       const ReferenceSet& refs, const MatchedReference& matched,
                       const ToneMap& tm) {
    result["reference"] = {{"key", refs.result().key},
                           {"samples", refs.result().acc.samples},
                           {"rel_error", ref::meanRelativeStdError(refs.result().acc)},
                           {"matched", matched.name}};
    result["reference"].update(writeReferencePreview(c, *run.scene, matched, tm));
}

/**
 * The static frame's metrics against the references (matched, full, bounce ladder, direct
 * light, bounce floors), its EXR and PNG files and result["outputs"].
 */
void addStaticMetricsAndOutputs(Context& c, nlohmann::ordered_json& result,
                                const std::vector<ImageLayer>& layers, const ReferenceSet& refs,
                                const MatchedReference& matched, int bounces, const ToneMap& tm,
                                const fs::path& tmp) {
    result["metrics"] = computeRunMetrics(layers, matched, bounces, c.config.metrics, tm, tmp);
    result["metrics"]["final_vs_bounces"] = computeBounceLadder(layers, refs, c.config.metrics, tm);
    result["metrics"]["direct"] = computeDirectMetrics(layers, refs.match(0), c.config.metrics, tm);
    result["metrics"]["bounce_floors"] = computeBounceFloors(refs, c.config.metrics, tm);
    writeExrWithMainImage((tmp / "output.exr").string(), layers, "final",
                          {{kPixelFilterAttribute, "center"}});
    writePngTonemapped((tmp / "final.png").string(), layers[0].image, tm);
    writePngTonemapped((tmp / "indirect.png").string(), layers[1].image, tm);
    result["outputs"] = {{"exr", "output.exr"},
                         {"final_png", "final.png"},
                         {"indirect_png", "indirect.png"},
                         {"flip_png", "flip.png"},
                         {"flip_full_png", "flip_full.png"}};
}

/**
 * The equal-time path-tracer baseline (pt_baseline.h): the reference renderer at `spp` samples
 * per pixel on this CPU, compared with the same references and metrics as any technique. It
 * claims every bounce. Static scenes only.
 */
std::string executePathTracerRun(Context& c, const RunSpec& run, const std::string& key,
                                 size_t position, size_t count) {
    const Scene& scene = c.scenes.get(*run.scene);
    const fs::path tmp = c.store.beginRun(key);
    nlohmann::ordered_json result;
    beginResult(c, result, run, key, scene);
    nlohmann::ordered_json swept = nlohmann::ordered_json::object();
    for (const auto& [k, v] : run.swept)
        swept[k] = v;
    result["technique"] = {
        {"id", kPathTracerId},
        {"description",
         "the reference path tracer at a small sample count, on the CPU (Embree, "
         "TBB): the equal-time baseline"},
        {"citation", ""},
        {"indirect_bounces", kAllBounces},
        {"params", run.params.toOrderedJson()},
        {"swept", swept}};
    result["provenance"] = cli::provenanceJson(c.options.commandLine);
    result["config_hash"] = c.configHash;
    const nlohmann::ordered_json prov = result["provenance"];
    result["device"] = {{"name", prov.value("cpu", std::string("CPU")) + " (path tracer)"},
                        {"type", "cpu_path_tracer"}};
    result["host"] = hostName();
    if (scene.animation.animated()) {
        result["reason"] = "the path-tracer baseline times static frames only";
        return commitResult(c, result, tmp, key, {.supported = false});
    }
    const ReferenceSet& refs = referenceFor(c, *run.scene, scene);
    const MatchedReference matched = refs.match(kAllBounces);
    const ToneMap tm = runToneMap(c, scene);
    addReferenceBlock(c, result, run, refs, matched, tm);
    std::fprintf(stderr, "[gilab] run %zu/%zu %s on %s (spp %d)\n", position, count, kPathTracerId,
                 run.scene->label.c_str(), run.params.getInt("spp"));
    PtBaselineOutput pt = renderPtBaseline(
        scene, c.config.reference.settings, uint32_t(run.params.getInt("spp")),
        uint64_t(run.params.getInt("seed")), warmupFrames(c, run), timedFrames(c, run), c.cancel);
    size_t nonFinite = 0;
    result["nonfinite"] = cli::finiteJson(pt.layers, &nonFinite);
    result["timing"] = pt.timing;
    result["stats"] = pt.stats;
    addStaticMetricsAndOutputs(c, result, pt.layers, refs, matched, kAllBounces, tm, tmp);
    return commitResult(c, result, tmp, key, {.supported = true, .nonFinitePixels = nonFinite});
}

std::string executeRun(Context& c, const RunSpec& run, const std::string& key, size_t position,
                       size_t count) {
    if (run.techniqueId == kPathTracerId) return executePathTracerRun(c, run, key, position, count);
    const Scene& scene = c.scenes.get(*run.scene);
    const TechniqueInfo& info = TechniqueRegistry::instance().get(run.techniqueId);
    const fs::path tmp = c.store.beginRun(key);

    nlohmann::ordered_json result;
    beginResult(c, result, run, key, scene);
    nlohmann::ordered_json swept = nlohmann::ordered_json::object();
    for (const auto& [k, v] : run.swept)
        swept[k] = v;
    result["technique"] = {{"id", info.id},
                           {"description", info.description},
                           {"citation", info.citation},
                           {"indirect_bounces", claimedBounces(info, run.params)},
                           {"params", run.params.toOrderedJson()},
                           {"swept", swept}};
    result["shared_params"] = run.shared.toOrderedJson();
    result["provenance"] = cli::provenanceJson(c.options.commandLine);
    result["config_hash"] = c.configHash;
    result["device"] = cli::deviceJson(c.vk);
    result["host"] = hostName();  // the report groups timings by device and names the nodes

    // Destroyed before the validation messages are collected, so they include its teardown.
    auto harness =
        std::make_unique<FrameHarness>(c.vk, scene, run.techniqueId, run.params, run.shared);
    if (!harness->support().supported) {
        result["reason"] = harness->support().reason;
        harness.reset();
        return commitResult(c, result, tmp, key, {.supported = false});
    }

    const ReferenceSet& refs = referenceFor(c, *run.scene, scene);
    const MatchedReference matched = refs.match(claimedBounces(info, run.params));
    const ToneMap tm = runToneMap(c, scene);
    addReferenceBlock(c, result, run, refs, matched, tm);

    const int timed = timedFrames(c, run);
    Progress progress("run " + std::to_string(position) + "/" + std::to_string(count) + " " +
                          info.id + " on " + run.scene->label,
                      size_t(warmupFrames(c, run) + timed));
    SetupTiming setup;
    std::vector<FrameTiming> frames;
    WarmupResult warmup;
    const int warm = warmupFrames(c, run);
    const int total = warm + timed;
    try {
        setup = harness->setup();
        warmup =
            harness->warmUp(warm, [&](int i) { progress.update(size_t(std::min(i + 1, warm))); });
        for (int i = warm; i < total; ++i) {
            frames.push_back(harness->renderFrame());
            progress.update(size_t(i + 1));
        }
        // Noisy frame times: more frames until the IQR is within target (docs/timing.md).
        while (int(frames.size()) < std::max(c.config.timing.frameLimit(), timed) &&
               cli::frameGpuIqrOverMedian(frames) > c.config.timing.targetIqr)
            frames.push_back(harness->renderFrame());
    } catch (const DeviceLimitError& e) {  // valid parameters this device cannot run
        progress.finish();
        result["reason"] = std::string("device limit: ") + e.what();
        harness.reset();
        return commitResult(c, result, tmp, key, {.supported = false});
    }
    progress.finish();

    std::vector<ImageLayer> layers = harness->readLayers();
    nlohmann::ordered_json sameVpl = nullptr;
    if (c.config.metrics.sameVplReference)
        sameVpl = computeSameVplReference(*harness, harness->scene(), layers, tm);
    size_t nonFinite = 0;
    result["nonfinite"] = cli::finiteJson(layers, &nonFinite);
    result["timing"] = cli::timingJson(setup, frames, warmup);
    {
        const double spread = cli::frameGpuIqrOverMedian(frames);
        nlohmann::ordered_json& t = result["timing"];
        t["frames_requested"] = timed;
        t["target_iqr"] = c.config.timing.targetIqr;
        t["iqr_over_median"] = std::isfinite(spread) ? nlohmann::ordered_json(spread) : nullptr;
        t["noisy"] = std::isfinite(spread) && spread > c.config.timing.targetIqr;
    }
    std::optional<SequenceResult> sequence;
    if (scene.animation.animated()) {
        // Frames 1..N-1 in order after the static frames at frame 0 (docs/experiments.md).
        const std::vector<int> measured =
            measuredFrames(scene.animation.frameCount, c.config.reference.frameStep);
        SequenceInputs in{scene,
                          claimedBounces(info, run.params),
                          measured,
                          layers,
                          [&](int f) -> const ReferenceSet& {
                              const Scene frameScene = sceneAtFrame(scene, f);
                              const ReferenceSet& set = referenceFor(c, *run.scene, frameScene, f);
                              writeReferenceFramePreview(c, *run.scene, f, set, tm);
                              return set;
                          },
                          c.config.metrics,
                          tm,
                          tmp};
        sequence = runSequence(*harness, in);
        nonFinite += sequence->nonFinitePixels;
        result["timing"].update(sequence->timing);
        result["animation"] = {{"frames", scene.animation.frameCount},
                               {"duration_s", scene.animation.duration},
                               {"moves", animationMoves(scene)},
                               {"measured_frames", measured},
                               {"update", sequence->update}};
    }
    result["memory"] = cli::memoryJson(harness->memory());
    result["skipped_passes"] = harness->skipped();
    result["notes"] = harness->notes();
    result["stats"] = nlohmann::ordered_json::object();
    for (const auto& [name, value] : harness->stats())
        result["stats"][name] = value;
    harness.reset();
    addStaticMetricsAndOutputs(c, result, layers, refs, matched, claimedBounces(info, run.params),
                               tm, tmp);
    if (!sameVpl.is_null()) result["metrics"]["same_vpl"] = sameVpl;
    if (sequence) {
        result["metrics"]["sequence"] = sequence->metrics;
        result["outputs"]["frames_png"] = sequence->framePngs;
        if (!sequence->temporalPng.empty())
            result["outputs"]["temporal_png"] = sequence->temporalPng;
        nlohmann::ordered_json refFrames = nlohmann::ordered_json::array();
        for (int f : result["animation"]["measured_frames"])
            refFrames.push_back("../../references/" + sanitizeLabel(run.scene->label) + "/frames/" +
                                framePreviewName(f));
        result["reference"]["frames_png"] = refFrames;
    }
    return commitResult(c, result, tmp, key, {.supported = true, .nonFinitePixels = nonFinite});
}

/** --references-only: the shard's share of the config's distinct references, each obtained
 *  under the cache's lock (rendered once, whoever asks). */
RunnerSummary renderReferences(const ExperimentConfig& config, const std::vector<RunSpec>& runs,
                               const RunnerOptions& options, const std::atomic<bool>* cancel,
                               RunnerSummary summary) {
    SceneCache scenes;
    const std::vector<ReferenceTask> tasks = referenceTasks(config, runs, scenes);
    summary.referencesTotal = tasks.size();
    ref::ReferenceCache cache(options.referenceCacheDir.empty()
                                  ? ref::ReferenceCache::defaultDir()
                                  : fs::path(options.referenceCacheDir));
    for (size_t i = 0; i < tasks.size(); ++i) {
        if (int(i % size_t(options.shardCount)) != options.shardIndex) continue;
        ++summary.referencesInShard;
        if (options.dryRun) {
            std::printf("reference %zu: %s\n", i,
                        referenceId(*tasks[i].entry, tasks[i].frame).c_str());
            continue;
        }
        if (cancel && cancel->load()) {
            summary.cancelled = true;
            break;
        }
        const Scene& base = scenes.get(*tasks[i].entry);
        const Scene scene = tasks[i].frame < 0 ? base : sceneAtFrame(base, tasks[i].frame);
        try {
            const ref::ReferenceResult r =
                obtainSceneReference(config, options, &cache, cancel, scene,
                                     referenceId(*tasks[i].entry, tasks[i].frame));
            if (r.renderedSamples > 0) ++summary.referencesRendered;
        } catch (const ReferenceInterrupted&) {
            summary.cancelled = true;
            break;
        }
    }
    return summary;
}

}  // namespace

std::pair<int, int> parseShard(const std::string& text) {
    const size_t slash = text.find('/');
    int i = -1, n = 0;
    const bool ok =
        slash != std::string::npos &&
        std::from_chars(text.data(), text.data() + slash, i).ptr == text.data() + slash &&
        std::from_chars(text.data() + slash + 1, text.data() + text.size(), n).ptr ==
            text.data() + text.size();
    if (!ok || n < 1 || i < 0 || i >= n)
        throw Error("--shard \"" + text + "\": expected i/N with 0 <= i < N");
    return {i, n};
}

RunnerSummary runExperiment(const RunnerOptions& options, const std::atomic<bool>* cancel) {
    Progress::setQuiet(options.quiet);
    const ExperimentConfig config = loadExperimentConfig(options.configPath);
    const std::vector<RunSpec> runs = expandRuns(config);

    RunnerSummary summary;
    summary.total = runs.size();
    summary.dir = fs::path(options.outRoot) / config.name;
    RunStore store(summary.dir, !options.dryRun && !options.referencesOnly);

    std::ifstream configIn(options.configPath);
    const std::string configText((std::istreambuf_iterator<char>(configIn)), {});
    nlohmann::ordered_json experiment = {{"name", config.name},
                                         {"description", config.description},
                                         {"config_path", options.configPath},
                                         {"config_hash", hashHex128(configText)},
                                         {"config", parseJsonText(configText, options.configPath)},
                                         {"runs_total", runs.size()},
                                         {"gilab_version", build::kVersion},
                                         {"git_commit", build::kGitCommit}};

    if (options.referencesOnly) return renderReferences(config, runs, options, cancel, summary);

    std::vector<const RunSpec*> mine;
    for (const RunSpec& r : runs)
        if (int(r.index % size_t(options.shardCount)) == options.shardIndex) mine.push_back(&r);
    summary.inShard = mine.size();

    SceneCache probeScenes;
    std::vector<std::string> keys;
    for (const RunSpec* r : mine)
        keys.push_back(hashHex128(runIdentity(config, *r, probeScenes.get(*r->scene)).dump()));
    if (options.dryRun) {
        printDryRun(mine, keys, store);
        return summary;
    }

    summary.rowsRepaired = store.addMissingRows();
    size_t pending = 0;
    for (const std::string& key : keys)
        pending += store.isFinished(key) ? 0 : 1;
    if (pending == 0) {
        summary.alreadyFinished = mine.size();
        return summary;  // nothing to do: no device, no probe
    }

    vk::ContextOptions vkOptions;
    vkOptions.validation = options.validation;
    vkOptions.deviceFilter = options.device;
    vk::Context vk(vkOptions);
    std::unique_ptr<ref::ReferenceCache> cache = std::make_unique<ref::ReferenceCache>(
        options.referenceCacheDir.empty() ? ref::ReferenceCache::defaultDir()
                                          : fs::path(options.referenceCacheDir));
    experiment["device"] = cli::deviceJson(vk);
    experiment["instrumentation"] =
        measureInstrumentationOverhead(vk, probeScenes.get(config.scenes.front()));
    experiment["validation"] = cli::takeValidationJson(vk);  // before the runs: the probe's
    summary.validationOutsideRuns = cli::validationMessageCount(experiment["validation"]);
    if (summary.validationOutsideRuns > 0)
        std::fprintf(stderr,
                     "gilab: %u Vulkan validation messages before the runs (timestamp probe; "
                     "see \"validation\" in %s)\n",
                     summary.validationOutsideRuns,
                     (summary.dir / "experiment.json").string().c_str());
    writeFileAtomic(summary.dir / ("experiment.json"), experiment.dump(2));

    Context c{config, options, store, vk,     cache.get(),
              {},     {},      {},    cancel, experiment["config_hash"].get<std::string>()};
    // Each run is claimed (its lock) before it starts, so processes sharing the folder never
    // run the same key at once. Runs another process holds are deferred, then waited for at
    // the end: when this process exits, every run of its shard is finished (docs/cluster.md).
    std::vector<size_t> deferred;
    auto attempt = [&](size_t i, std::optional<FileLock> claim) {
        if (store.isFinished(keys[i])) {
            ++(claim ? summary.alreadyFinished : summary.doneElsewhere);
            return true;
        }
        std::string status;
        try {
            status = executeRun(c, *mine[i], keys[i], i + 1, mine.size());
        } catch (const ReferenceInterrupted&) {
            summary.cancelled = true;  // nothing of this run is committed; the next run redoes it
            return false;
        }
        ++summary.ran;
        if (status == "unsupported") ++summary.unsupported;
        if (status == "nonfinite") ++summary.nonfinite;
        if (status == "invalid") ++summary.invalid;
        return true;
    };
    for (size_t i = 0; i < mine.size(); ++i) {
        if (cancel && cancel->load()) {
            summary.cancelled = true;
            return summary;
        }
        if (store.isFinished(keys[i])) {
            ++summary.alreadyFinished;
            continue;
        }
        std::optional<FileLock> claim = store.tryClaim(keys[i]);
        if (!claim) {
            deferred.push_back(i);
            continue;
        }
        if (!attempt(i, std::move(claim))) return summary;
    }
    for (size_t i : deferred) {
        if (!store.isFinished(keys[i]))
            std::fprintf(stderr, "[gilab] run %zu is running in another process; waiting for it\n",
                         mine[i]->index);
        std::optional<FileLock> claim = store.claim(keys[i], cancel);
        if (!claim) {
            summary.cancelled = true;
            return summary;
        }
        // Finished by the other process, or (it died) run here
        if (store.isFinished(keys[i])) {
            ++summary.doneElsewhere;
            continue;
        }
        if (!attempt(i, std::move(claim))) return summary;
    }
    return summary;
}

std::vector<std::string> listReferences(const std::string& configPath) {
    const ExperimentConfig config = loadExperimentConfig(configPath);
    SceneCache scenes;
    std::vector<std::string> ids;
    for (const ReferenceTask& t : referenceTasks(config, expandRuns(config), scenes))
        ids.push_back(referenceId(*t.entry, t.frame));
    return ids;
}

}  // namespace gilab::exp
