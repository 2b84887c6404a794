// `gilab bench direct`: how exact the shared direct light is on every shipped scene and variant
// (energy against the path tracer's emission + direct, light leaked into pixels it has in
// shadow, HDR-FLIP) and what it costs per frame. Prints a table; --out adds a JSON file.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>

#include <nlohmann/json.hpp>

#include "core/passes/shared_passes.h"
#include "core/scene/scene_loader.h"
#include "core/technique/frame_harness.h"
#include "core/technique/registry.h"
#include "core/util/build_info.h"
#include "core/util/error.h"
#include "core/util/progress.h"
#include "core/util/stats.h"
#include "core/util/strings.h"
#include "core/vk/context.h"
#include "experiments/cli/cli.h"
#include "experiments/cli/leak_causes.h"
#include "experiments/cli/light_placements.h"
#include "experiments/metrics/direct_accuracy.h"
#include "experiments/metrics/metrics.h"
#include "experiments/runner/run_metadata.h"
#include "reference/cache.h"

namespace gilab::cli {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

/** The scene folder: ./scenes, else the source tree's. */
fs::path scenesDir() {
    if (fs::is_directory("scenes")) return "scenes";
    return fs::path(build::kSourceDir) / "scenes";
}

/** "file.json" and "file.json#variant" for every variant of a scene description. */
std::vector<std::string> withVariants(const fs::path& file) {
    std::vector<std::string> out{file.string()};
    std::ifstream in(file);
    const Json j = Json::parse(in, nullptr, false);
    if (j.is_object() && j.contains("variants") && j["variants"].is_object())
        for (const auto& [name, _] : j["variants"].items())
            out.push_back(file.string() + "#" + name);
    return out;
}

/** Every shipped scene file (scenes, scenes/stress: *.json), sorted per folder. */
std::vector<std::string> shippedSceneFiles() {
    std::vector<std::string> out;
    for (const fs::path& dir : {scenesDir(), scenesDir() / "stress"}) {
        std::vector<fs::path> files;
        for (const fs::directory_entry& e : fs::directory_iterator(dir))
            if (e.is_regular_file() && e.path().extension() == ".json") files.push_back(e.path());
        std::sort(files.begin(), files.end());
        for (const fs::path& f : files)
            out.push_back(f.string());
    }
    return out;
}

/** Every shipped scene description with its variants. */
std::vector<std::string> shippedScenes() {
    std::vector<std::string> out;
    for (const std::string& f : shippedSceneFiles())
        for (const std::string& s : withVariants(f))
            out.push_back(s);
    return out;
}

/** "sun, spot", "area (2 triangles)": what lights the scene directly. */
std::string lightSummary(const Scene& scene, uint32_t areaSamples) {
    std::map<std::string, int> count;
    for (const Light& l : scene.lights)
        ++count[l.type == LightType::Point ? "point" : l.type == LightType::Spot ? "spot" : "sun"];
    std::vector<std::string> parts;
    for (const auto& [kind, n] : count)
        parts.push_back(n > 1 ? std::to_string(n) + " " + kind : kind);
    if (scene.caps.hasEmissive) parts.push_back("area/" + std::to_string(areaSamples));
    return parts.empty() ? "none" : joinStrings(parts, "+");
}

Image addLayers(const Image& a, const Image& b) {
    Image sum = a;
    for (size_t i = 0; i < sum.values().size(); ++i)
        sum.values()[i] += b.values()[i];
    return sum;
}

const Image& layer(const std::vector<ImageLayer>& layers, const std::string& name) {
    for (const ImageLayer& l : layers)
        if (l.name == name) return l.image;
    throw Error("no layer \"" + name + "\"");
}

struct Row {
    std::string scene, size, lights, status;
    metrics::DirectAccuracy accuracy;
    double flip = 0.0;
    double rasterMean = 0.0;         // mean luminance of the raster's emission + direct
    double referenceRelError = 0.0;  // mean relative standard error of the reference's layers
    uint64_t referenceSpp = 0;
    double directMs = 0.0, directIqr = 0.0, shadowSetupMs = 0.0;
    Image raster, reference;  // emission + direct of both, kept for the leak classification
};

Row benchLoaded(vk::Context& ctx, const Scene& scene, const std::string& label,
                const BenchDirectOptions& options, const ref::ReferenceCache* cache);

Row benchScene(vk::Context& ctx, const std::string& spec, const BenchDirectOptions& options,
               const ref::ReferenceCache* cache) {
    Scene scene;
    try {
        scene = loadScene(spec);
    } catch (const Error& e) {
        Row row;
        row.scene = spec;
        row.status = std::string("skipped: ") + e.what();
        return row;
    }
    applyResolutionOverride(scene, options.resolution);
    return benchLoaded(ctx, scene, spec, options, cache);
}

Row benchLoaded(vk::Context& ctx, const Scene& scene, const std::string& label,
                const BenchDirectOptions& options, const ref::ReferenceCache* cache) {
    Row row;
    row.scene = label;
    ParamSet params = TechniqueRegistry::instance().defaultParams("direct");
    ParamSet shared = defaultSharedParams();
    applyAssignments(options.assignments, params, shared);
    row.size = std::to_string(scene.settings.width) + "x" + std::to_string(scene.settings.height);
    row.lights = lightSummary(scene, sharedSettingsFromParams(shared).areaLightSamples);

    // The raster: set-up (shadow maps), then timed frames
    FrameHarness harness(ctx, scene, "direct", params, shared);
    if (!harness.support().supported) {
        row.status = "unsupported: " + harness.support().reason;
        return row;
    }
    const SetupTiming setup = harness.setup();
    for (const vk::PassTime& p : setup.passes)
        if (p.name == "shadow_maps") row.shadowSetupMs = p.gpuMs;
    std::vector<double> directMs;
    for (int i = 0; i < 1 + options.frames; ++i) {
        const FrameTiming t = harness.renderFrame();
        if (i == 0) continue;  // warm-up
        for (const vk::PassTime& p : t.passes)
            if (p.name == "direct_light") directMs.push_back(p.gpuMs);
    }
    const Summary q = summarize(directMs);
    row.directMs = q.median;
    row.directIqr = q.iqr();
    const std::vector<ImageLayer> layers = harness.readLayers();
    const Image raster = addLayers(layer(layers, "direct"), layer(layers, "emission"));

    // The path tracer's emission + direct at the rasteriser's footprint. Delta lights are exact
    // at one sample; emitters need samples.
    ref::ReferenceSettings settings;
    settings.maxBounces = 0;
    settings.pixelFilter = ref::PixelFilter::Center;
    ref::StopCriteria stop;
    stop.maxSamples = scene.caps.hasEmissive ? options.areaSpp : 1;
    const ref::ReferenceResult r = ref::obtainReference(scene, settings, stop, cache);
    const std::vector<ImageLayer> refLayers = ref::meanLayers(r.acc);
    const Image reference = addLayers(layer(refLayers, "direct"), layer(refLayers, "emission"));
    row.referenceSpp = r.acc.samples;
    row.referenceRelError =
        scene.caps.hasEmissive ? ref::meanRelativeStdError(r.acc, ref::Layer::Direct) : 0.0;

    row.accuracy = metrics::directAccuracy(raster, reference);
    row.rasterMean = meanLuminance(raster);
    row.flip = metrics::computeHdrFlip(raster, reference, metrics::kDefaultPpd).stats.mean;
    row.status = "ok";
    row.raster = raster;
    row.reference = reference;
    return row;
}

/** The measured causes of a row's leak (leak_causes.h) where its scene is lit by one point or
 *  spot light and nothing else; nullopt otherwise. */
std::optional<std::string> leakCauseText(const Scene& scene, const Image& raster,
                                         const Image& reference,
                                         const BenchDirectOptions& options) {
    if (scene.lights.size() != 1 || scene.caps.hasEmissive ||
        scene.lights[0].type == LightType::Directional)
        return std::nullopt;
    ParamSet params = TechniqueRegistry::instance().defaultParams("direct");
    ParamSet shared = defaultSharedParams();
    applyAssignments(options.assignments, params, shared);
    const SharedPassSettings settings = sharedSettingsFromParams(shared);
    ShadowModel model;
    model.resolution = settings.shadow.resolution;
    model.constantBias = settings.shadow.constantBias;
    return describeLeakCauses(classifyLeaks(scene, raster, reference, model));
}

Json rowJson(const Row& r) {
    Json j{{"scene", r.scene}, {"status", r.status}};
    if (r.status != "ok") return j;
    auto num = [](double v) { return std::isfinite(v) ? Json(v) : Json(nullptr); };
    j["resolution"] = r.size;
    j["lights"] = r.lights;
    j["energy_ratio"] = num(r.accuracy.energyRatio);
    j["shadow_leak"] = num(r.accuracy.shadowLeak);
    j["missing"] = num(r.accuracy.missing);
    j["hdr_flip"] = num(r.flip);
    j["raster_mean_luminance"] = num(r.rasterMean);
    j["reference_spp"] = r.referenceSpp;
    j["reference_rel_error"] = num(r.referenceRelError);
    j["direct_light_ms"] = num(r.directMs);
    j["direct_light_iqr_ms"] = num(r.directIqr);
    j["shadow_maps_setup_ms"] = num(r.shadowSetupMs);
    return j;
}

}  // namespace

double percentile(std::vector<double> v, double q) {
    if (v.empty()) return std::nan("");
    std::sort(v.begin(), v.end());
    const double x = q * double(v.size() - 1);
    const size_t i = size_t(x);
    const double f = x - double(i);
    return i + 1 < v.size() ? v[i] * (1.0 - f) + v[i + 1] * f : v[i];
}

/** --placements N: N random point and spot lights per scene (light_placements.h), each scored
 *  like a shipped scene; per scene the median and 95th percentile of the leak, the median
 *  energy and the worst placement. */
int runPlacements(vk::Context& ctx, const BenchDirectOptions& options,
                  const ref::ReferenceCache* cache, Json& rows, Json& summaries) {
    const std::vector<std::string> files =
        options.scenes.empty() ? shippedSceneFiles() : options.scenes;
    std::vector<double> allLeaks, allEnergies;
    for (const std::string& spec : files) {
        Scene scene;
        try {
            scene = loadScene(spec);
        } catch (const Error& e) {
            std::printf("%-48s skipped: %s\n", spec.c_str(), e.what());
            continue;
        }
        applyResolutionOverride(scene, options.resolution);
        const std::vector<LightPlacement> placements =
            randomLightPlacements(scene, options.placementSeed, options.placements);
        std::vector<double> leaks, energies;
        double worstLeak = -1.0;
        std::string worst;
        std::optional<Scene> worstScene;
        Image worstRaster, worstReference;
        for (size_t k = 0; k < placements.size(); ++k) {
            const Scene lit = withOnlyLight(scene, placements[k].light);
            const std::string label = spec + " [" + std::to_string(k) + "]";
            const Row r = benchLoaded(ctx, lit, label, options, cache);
            Json j = rowJson(r);
            j["placement"] = placements[k].label;
            rows.push_back(j);
            if (r.status != "ok" || !std::isfinite(r.accuracy.energyRatio)) {
                std::printf("%-48s %s: %s\n", label.c_str(), placements[k].label.c_str(),
                            r.status == "ok" ? "black reference" : r.status.c_str());
                continue;
            }
            leaks.push_back(100.0 * r.accuracy.shadowLeak);
            energies.push_back(r.accuracy.energyRatio);
            if (100.0 * r.accuracy.shadowLeak > worstLeak) {
                worstLeak = 100.0 * r.accuracy.shadowLeak;
                worst = placements[k].label;
                worstScene = lit;
                worstRaster = r.raster;
                worstReference = r.reference;
            }
            if (!options.quiet)
                std::printf("%-48s %-7.4f %7.3f %%  %s\n", label.c_str(), r.accuracy.energyRatio,
                            100.0 * r.accuracy.shadowLeak, placements[k].label.c_str());
        }
        if (leaks.empty()) continue;
        allLeaks.insert(allLeaks.end(), leaks.begin(), leaks.end());
        allEnergies.insert(allEnergies.end(), energies.begin(), energies.end());
        const double median = percentile(leaks, 0.5), p95 = percentile(leaks, 0.95),
                     energy = percentile(energies, 0.5);
        std::printf(
            "%-48s %3zu placements: leak median %.3f %%, p95 %.3f %%; energy median %.4f "
            "(%.4f-%.4f); worst %.3f %% at %s\n",
            spec.c_str(), leaks.size(), median, p95, energy,
            *std::min_element(energies.begin(), energies.end()),
            *std::max_element(energies.begin(), energies.end()), worstLeak, worst.c_str());
        // The worst placement's measured cause (leak_causes.h)
        const std::string causeText =
            leakCauseText(*worstScene, worstRaster, worstReference, options)
                .value_or("not classified");
        std::printf("%-48s worst placement's leak: %s\n", "", causeText.c_str());
        std::fflush(stdout);
        summaries.push_back({{"scene", spec},
                             {"worst_leak_causes", causeText},
                             {"placements", leaks.size()},
                             {"leak_median_percent", median},
                             {"leak_p95_percent", p95},
                             {"energy_median", energy},
                             {"worst_leak_percent", worstLeak},
                             {"worst_placement", worst}});
    }
    if (!allLeaks.empty())
        std::printf(
            "all scenes, %zu placements: leak median %.3f %%, p95 %.3f %%; energy median "
            "%.4f (targets: <= 0.3 %%, <= 1 %%, 1 +- 0.02)\n",
            allLeaks.size(), percentile(allLeaks, 0.5), percentile(allLeaks, 0.95),
            percentile(allEnergies, 0.5));
    return kExitOk;
}

int runBenchDirect(const BenchDirectOptions& options) {
    Progress::setQuiet(options.quiet);
    std::vector<std::string> scenes = options.scenes.empty() ? shippedScenes() : options.scenes;
    {  // bad --set keys fail before any work
        ParamSet p = TechniqueRegistry::instance().defaultParams("direct");
        ParamSet s = defaultSharedParams();
        applyAssignments(options.assignments, p, s);
    }
    std::optional<ref::ReferenceCache> cache;
    if (!options.noCache)
        cache.emplace(options.cacheDir.empty() ? ref::ReferenceCache::defaultDir()
                                               : fs::path(options.cacheDir));
    vk::ContextOptions ctxOptions;
    ctxOptions.deviceFilter = options.device;
    vk::Context ctx(ctxOptions);

    std::printf("shared direct light vs the path tracer's emission + direct (centre filter), %s\n",
                ctx.deviceName().c_str());
    std::printf("settings: %s\n", options.assignments.empty()
                                      ? "defaults"
                                      : joinStrings(options.assignments, " ").c_str());
    std::printf("%-48s %-8s %-14s %7s %8s %8s %8s %9s %10s\n", "scene", "size", "lights", "energy",
                "leak %", "miss %", "HDR-FLIP", "direct ms", "shadows ms");
    Json rows = Json::array();
    Json summaries = Json::array();
    if (options.placements > 0) {
        runPlacements(ctx, options, cache ? &*cache : nullptr, rows, summaries);
        scenes.clear();
    }
    for (const std::string& spec : scenes) {
        const Row r = benchScene(ctx, spec, options, cache ? &*cache : nullptr);
        rows.push_back(rowJson(r));
        if (r.status != "ok") {
            std::printf("%-48s %s\n", r.scene.c_str(), r.status.c_str());
            continue;
        }
        if (std::isfinite(r.accuracy.energyRatio)) {
            std::printf("%-48s %-8s %-14s %7.4f %8.3f %8.3f %8.4f %9.2f %10.1f\n", r.scene.c_str(),
                        r.size.c_str(), r.lights.c_str(), r.accuracy.energyRatio,
                        100.0 * r.accuracy.shadowLeak, 100.0 * r.accuracy.missing, r.flip,
                        r.directMs, r.shadowSetupMs);
            if (r.accuracy.shadowLeak > 1e-3) {
                Scene scene = loadScene(spec);
                applyResolutionOverride(scene, options.resolution);
                if (const auto text = leakCauseText(scene, r.raster, r.reference, options)) {
                    std::printf("%-48s leak: %s\n", "", text->c_str());
                    rows.back()["leak_causes"] = *text;
                }
            }
        } else {  // nothing reaches the camera in the path tracer: the raster's light is a leak
            std::printf(
                "%-48s %-8s %-14s %7s %8s %8s %8.4f %9.2f %10.1f  black reference; "
                "raster mean %.3g over %zu pixels\n",
                r.scene.c_str(), r.size.c_str(), r.lights.c_str(), "-", "-", "-", r.flip,
                r.directMs, r.shadowSetupMs, r.rasterMean, r.accuracy.pixels);
        }
        std::fflush(stdout);
    }
    std::printf(
        "energy: mean luminance over the path tracer's; leak: light in pixels the path tracer has "
        "at 0 (shadow, outside a cone), %% of its total; miss: light missing from lit pixels, %%; "
        "direct ms: median GPU time of the direct_light pass per frame; shadows ms: the one-time "
        "shadow_maps pass (docs/shared_passes.md)\n");
    if (!options.outDir.empty()) {
        fs::create_directories(options.outDir);
        Json out{{"device", ctx.deviceName()},
                 {"settings", options.assignments},
                 {"area_spp", options.areaSpp},
                 {"provenance", provenanceJson(options.commandLine)},
                 {"scenes", rows}};
        if (options.placements > 0) {
            out["placements"] = options.placements;
            out["placement_seed"] = options.placementSeed;
            out["placement_summaries"] = summaries;
        }
        const fs::path path = fs::path(options.outDir) / "bench_direct.json";
        std::ofstream(path) << out.dump(2) << "\n";
        std::printf("wrote %s\n", path.string().c_str());
    }
    return kExitOk;
}

}  // namespace gilab::cli
