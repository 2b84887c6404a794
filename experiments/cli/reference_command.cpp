// `gilab reference`: the path-traced ground truth of one scene, through the reference cache ->
// <out>/reference.exr (mean + stderr layers), reference.png, reference.json [, convergence.csv]
#include <unistd.h>
#include <algorithm>
#include <charconv>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>

#include "core/image/image_io.h"
#include "core/scene/animation.h"
#include "core/util/error.h"
#include "core/util/progress.h"
#include "experiments/cli/cli.h"
#include "experiments/cli/interrupt.h"
#include "experiments/runner/run_metadata.h"
#include "experiments/runner/run_sequence.h"
#include "reference/cache.h"

namespace gilab::cli {
namespace {

ref::Estimator parseEstimator(const std::string& name) {
    for (ref::Estimator e :
         {ref::Estimator::Mis, ref::Estimator::NeeOnly, ref::Estimator::BsdfOnly})
        if (name == ref::estimatorName(e)) return e;
    throw Error("--estimator \"" + name + "\": expected mis, nee or bsdf");
}

/** The "full" layer (else the unnamed or the first layer) of an EXR, as RGB at the scene size. */
Image loadLongReference(const std::string& path, const Scene& scene) {
    const std::vector<ImageLayer> layers = readExrLayers(path);
    const Image* image = findLayer(layers, "full");
    if (!image) image = findLayer(layers, "");
    if (!image && !layers.empty()) image = &layers.front().image;
    if (!image || image->channels() < 3)
        throw Error(path + ": --long-reference needs an RGB layer named \"full\"");
    if (image->width() != scene.settings.width || image->height() != scene.settings.height)
        throw Error(path + ": --long-reference is " + std::to_string(image->width()) + "x" +
                    std::to_string(image->height()) + ", the scene renders at " +
                    std::to_string(scene.settings.width) + "x" +
                    std::to_string(scene.settings.height));
    return image->channels() == 3 ? *image : image->channelRange(0, 3);
}

nlohmann::ordered_json curveJson(const std::vector<ref::ConvergencePoint>& curve) {
    nlohmann::ordered_json out = nlohmann::ordered_json::array();
    for (const ref::ConvergencePoint& p : curve)
        out.push_back({{"samples", p.samples},
                       {"seconds", p.seconds},
                       {"rel_error", p.relError},
                       {"rel_mse_vs_long", p.relMseVsLong}});  // NaN is written as null
    return out;
}

void writeCurveCsv(const std::string& path, const std::vector<ref::ConvergencePoint>& curve) {
    const std::string tmp = path + ".tmp-" + std::to_string(::getpid());
    {
        std::ofstream out(tmp);
        out << "samples,seconds,rel_error,rel_mse_vs_long\n";
        char line[160];
        for (const ref::ConvergencePoint& p : curve) {
            std::snprintf(line, sizeof line, "%llu,%.6g,%.9g,%.9g\n", (unsigned long long)p.samples,
                          p.seconds, p.relError, p.relMseVsLong);
            out << line;
        }
        if (!out) throw Error("cannot write " + tmp);
    }
    std::filesystem::rename(tmp, path);
}

std::string cacheSummary(const ref::ReferenceResult& r, bool cacheUsed) {
    if (!cacheUsed) return "no cache";
    if (r.cacheHit) return "cache hit";
    if (r.continuedFromSamples > 0)
        return "cache: continued from " + std::to_string(r.continuedFromSamples) + " spp";
    return "cache miss";
}

}  // namespace

/** The reference of one (static or frame) scene into `outDirPath`. */
int renderReference(const ReferenceOptions& options, const Scene& scene,
                    const std::string& outDirPath) {
    ref::ReferenceSettings settings;
    settings.maxBounces = options.maxBounces;
    settings.rouletteStartBounce = options.rouletteDepth;
    settings.rouletteThreshold = options.rouletteThreshold;
    settings.estimator = parseEstimator(options.estimator);
    settings.pixelFilter =
        options.pixelFilter == "center" ? ref::PixelFilter::Center : ref::PixelFilter::Box;
    settings.sampler =
        options.sampler == "sobol" ? ref::SamplerKind::Sobol : ref::SamplerKind::Independent;
    settings.sobolReplicate = options.sobolReplicate;
    settings.seed = options.seed;
    settings.batchSamples = options.batchSamples;
    ref::StopCriteria stop{options.spp, options.relError, options.seconds};
    if (stop.maxSamples == 0 && stop.targetRelError <= 0.0 && stop.maxSeconds <= 0.0) {
        stop.maxSamples = 64;
        std::fprintf(stderr,
                     "gilab: reference: no stop criterion given (--spp, --rel-error, --time); "
                     "using the default --spp 64\n");
    }

    Image longReference;
    if (!options.longReference.empty())
        longReference = loadLongReference(options.longReference, scene);

    std::optional<ref::ReferenceCache> cache;
    if (!options.noCache)
        cache.emplace(options.cacheDir.empty() ? ref::ReferenceCache::defaultDir()
                                               : std::filesystem::path(options.cacheDir));

    ref::ObtainOptions obtain;
    obtain.longReference = longReference.empty() ? nullptr : &longReference;
    obtain.sidecarExtra = {{"provenance", provenanceJson(options.commandLine)},
                           {"scene", sceneToJson(scene)}};
    std::optional<InterruptScope> interrupt;
    if (options.cancel) {
        obtain.cancel = options.cancel;
    } else {
        interrupt.emplace(
            "\ngilab: interrupted: finishing at the next batch and saving a partial result "
            "(a second Ctrl-C or SIGTERM aborts)\n");
        obtain.cancel = &interrupt->flag();
    }
    const ref::ReferenceResult r =
        ref::obtainReference(scene, settings, stop, cache ? &*cache : nullptr, obtain);
    interrupt.reset();  // from here on, Ctrl-C and SIGTERM kill as usual
    for (const std::string& w : r.warnings)
        std::fprintf(stderr, "gilab: warning: %s\n", w.c_str());

    // Outputs: EXR (mean + stderr), PNG (full, scene exposure), JSON, convergence curve
    const bool cancelled = r.reason == ref::StopReason::Cancelled;
    const std::filesystem::path outDir(outDirPath);
    std::filesystem::create_directories(outDir);
    const std::string base = (outDir / "reference").string();
    std::vector<ImageLayer> layers;
    size_t nonFinite = 0;
    nlohmann::ordered_json finite = nlohmann::ordered_json::object();
    if (r.acc.samples > 0) {  // cancelled before the first batch: the JSON alone
        layers = ref::meanLayers(r.acc);
        finite = finiteJson(layers, &nonFinite);
        for (ImageLayer& l : ref::stdErrorLayers(r.acc))
            layers.push_back(std::move(l));
        writeExrWithMainImage(
            base + ".exr", layers, "full",
            {{kPixelFilterAttribute, ref::pixelFilterName(settings.pixelFilter)}});
        ToneMap tm;
        tm.exposureEv = scene.settings.exposureEv;
        writePngTonemapped(base + ".png", layers.front().image, tm);
    }

    std::vector<ref::ConvergencePoint> curve = r.report.curve;
    if (obtain.longReference && r.cacheHit &&
        !layers.empty()) {  // nothing rendered: the final point only
        const double relError = ref::meanRelativeStdError(r.acc);
        curve.push_back({r.acc.samples, r.sidecar.value("seconds", 0.0), relError,
                         ref::relativeMse(layers.front().image, longReference)});
    }

    nlohmann::ordered_json meta = r.sidecar;
    meta["status"] = cancelled ? "partial" : r.sidecar.value("status", "complete");
    meta["cache"] = {{"key", r.key},
                     {"hit", r.cacheHit},
                     {"continued_from_samples", r.continuedFromSamples},
                     {"rendered_samples", r.renderedSamples},
                     {"dir", cache ? cache->entryDir(r.key).string() : std::string()},
                     {"enabled", cache.has_value()}};
    meta["this_run"] = {{"provenance", provenanceJson(options.commandLine)},
                        {"request", ref::stopCriteriaJson(stop)},
                        {"stop_reason", ref::stopReasonName(r.reason)},
                        {"seconds", r.report.seconds},
                        {"rays", r.report.rays.totalRays()},
                        {"warnings", r.warnings}};
    meta["nonfinite"] = finite;
    if (obtain.longReference) {
        meta["convergence"] = {{"long_reference", options.longReference},
                               {"curve", curveJson(curve)}};
        writeCurveCsv((outDir / "convergence.csv").string(), curve);
    }
    if (!layers.empty()) meta["outputs"] = {{"exr", base + ".exr"}, {"png", base + ".png"}};
    writeJsonAtomic(base + ".json", meta);

    // One-line summary
    const ref::RayStats& rays = r.report.rays;
    const double mrays = rays.seconds > 0.0 ? double(rays.totalRays()) / rays.seconds / 1e6 : 0.0;
    std::printf(
        "reference %s (%dx%d): %llu spp, %.2f s total (this run %llu spp in %.2f s, "
        "%.2f Mrays/s), rel error %.4g, %s, %s [key %.12s]\n",
        scene.name.c_str(), r.acc.width, r.acc.height, (unsigned long long)r.acc.samples,
        meta.value("seconds", 0.0), (unsigned long long)r.renderedSamples, r.report.seconds, mrays,
        ref::meanRelativeStdError(r.acc), ref::stopReasonName(r.reason),
        cacheSummary(r, cache.has_value()).c_str(), r.key.c_str());
    std::printf("  wrote %s.%s%s\n", base.c_str(), layers.empty() ? "json" : "{exr,png,json}",
                obtain.longReference ? " and convergence.csv" : "");
    if (r.acc.nonFiniteSamples > 0)
        std::fprintf(stderr,
                     "gilab: warning: %llu non-finite samples were dropped (added 0; see "
                     "\"nonfinite_samples\" in %s.json)\n",
                     (unsigned long long)r.acc.nonFiniteSamples, base.c_str());
    if (cancelled) {
        std::fprintf(stderr, "gilab: interrupted after %llu spp; partial result saved%s\n",
                     (unsigned long long)r.acc.samples,
                     cache && r.acc.samples > 0 ? " (and cached)" : "");
        return kExitInterrupted;
    }
    if (nonFinite) {
        std::fprintf(stderr, "gilab: %zu non-finite pixels (see \"nonfinite\" in %s.json)\n",
                     nonFinite, base.c_str());
        return kExitNonFinite;
    }
    return kExitOk;
}

/** "all", "every:K" (or "K"), or a comma list "0,4,8": frames of an N-frame animation. */
std::vector<int> parseFrameSelection(const std::string& text, int frameCount) {
    std::vector<int> frames;
    auto bad = [&]() {
        return UsageError("--frames \"" + text +
                          "\": expected all, every:K, K (every K-th frame) or a list like 0,4,8 "
                          "(the animation has frames 0.." +
                          std::to_string(frameCount - 1) + ")");
    };
    auto toInt = [&](const std::string& t) {
        int v = -1;
        const auto [ptr, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
        if (ec != std::errc() || ptr != t.data() + t.size()) throw bad();
        return v;
    };
    if (text == "all") return exp::measuredFrames(frameCount, 1);
    if (text.rfind("every:", 0) == 0 || text.find(',') == std::string::npos) {
        const int k = toInt(text.rfind("every:", 0) == 0 ? text.substr(6) : text);
        if (k < 1) throw bad();
        return exp::measuredFrames(frameCount, k);
    }
    size_t start = 0;
    while (start <= text.size()) {
        const size_t comma = text.find(',', start);
        const int f = toInt(text.substr(start, comma - start));
        if (f < 0 || f >= frameCount) throw bad();
        frames.push_back(f);
        if (comma == std::string::npos) break;
        start = comma + 1;
    }
    return frames;
}

int runReference(const ReferenceOptions& options) {
    Progress::setQuiet(options.quiet);
    checkOutputFolder("--out", options.outDir);  // before the render, not after it
    Scene scene = loadSceneOrDefault(options.scenePath);
    applyResolutionOverride(scene, options.resolution);
    for (const std::string& w : scene.warnings)
        std::fprintf(stderr, "gilab: %s: warning: %s\n", scene.name.c_str(), w.c_str());
    if (options.frames.empty()) return renderReference(options, scene, options.outDir);
    if (!scene.animation.animated())
        throw UsageError("--frames: " + scene.name + " has no animation (docs/scenes.md)");
    // One reference per selected frame, each cached under its own key (the frame's lights
    // and camera are part of it): re-running renders only what is missing.
    // One interrupt scope for every frame, so a signal between two frames also stops cleanly
    std::optional<InterruptScope> interrupt;
    ReferenceOptions frameOptions = options;
    if (!frameOptions.cancel) {
        interrupt.emplace(
            "\ngilab: interrupted: finishing at the next batch and saving a partial result "
            "(a second Ctrl-C or SIGTERM aborts)\n");
        frameOptions.cancel = &interrupt->flag();
    }
    int worst = kExitOk;
    for (int f : parseFrameSelection(options.frames, scene.animation.frameCount)) {
        if (frameOptions.cancel->load()) {
            std::fprintf(stderr, "gilab: interrupted before frame %d; earlier frames are kept\n",
                         f);
            return kExitInterrupted;
        }
        Scene frameScene = scene;
        applyFrameState(frameScene, frameState(scene, f));
        char dir[32];
        std::snprintf(dir, sizeof dir, "frame_%03d", f);
        std::printf("frame %d of %d (t = %.3f s):\n", f, scene.animation.frameCount,
                    scene.animation.frameTime(f));
        const int code = renderReference(frameOptions, frameScene,
                                         (std::filesystem::path(options.outDir) / dir).string());
        if (code == kExitInterrupted) return code;
        worst = std::max(worst, code);
    }
    return worst;
}

}  // namespace gilab::cli
