// `gilab bench reference`: path tracer ray rates vs raw Embree on the same rays, and the time
// to reach a relative MSE of 1e-3 against a long run. Prints tables; --out adds a JSON file.
#include <cstdio>
#include <filesystem>

#include <embree3/rtcore_config.h>

#include "core/util/build_info.h"
#include "core/util/error.h"
#include "core/util/progress.h"
#include "experiments/cli/cli.h"
#include "experiments/runner/run_metadata.h"
#include "reference/bench.h"

namespace gilab::cli {
namespace {

/** "scenes/sponza.json" from the working folder, else from the source tree. */
std::string defaultSponzaPath() {
    const std::string relative = "scenes/sponza.json";
    if (std::filesystem::exists(relative)) return relative;
    const std::string inSource = std::string(build::kSourceDir) + "/" + relative;
    return std::filesystem::exists(inSource) ? inSource : relative;
}

double mega(double perSecond) {
    return perSecond * 1e-6;
}

void printRenderTable(const std::vector<ref::BenchSceneResult>& results) {
    std::printf("\npath tracer (%d threads)\n", results.front().threads);
    std::printf("%-22s %-10s %9s %5s %8s %13s %13s %12s\n", "scene", "resolution", "triangles",
                "spp", "seconds", "closest Mr/s", "shadow Mr/s", "total Mr/s");
    for (const ref::BenchSceneResult& r : results) {
        const std::string res = std::to_string(r.width) + "x" + std::to_string(r.height);
        std::printf("%-22s %-10s %9zu %5llu %8.2f %13.2f %13.2f %12.2f\n", r.scene.c_str(),
                    res.c_str(), r.triangles, (unsigned long long)r.spp, r.rays.seconds,
                    mega(r.closestRaysPerSecond()), mega(r.shadowRaysPerSecond()),
                    mega(r.raysPerSecond()));
    }
}

void printReplayTable(const std::vector<ref::BenchSceneResult>& results) {
    std::printf("\nraw Embree, the same rays replayed (Mrays/s)\n");
    std::printf("%-22s %7s %9s %9s %9s %9s | %9s %9s %9s %9s\n", "scene", "threads", "Isect1",
                "Isect8", "Isect16", "Isect1M", "Occl1", "Occl8", "Occl16", "Occl1M");
    for (const ref::BenchSceneResult& r : results) {
        std::vector<int> threadCounts;
        for (const ref::ReplayRate& rate : r.replay.closest)
            if (threadCounts.empty() || threadCounts.back() != rate.threads)
                threadCounts.push_back(rate.threads);
        for (int t : threadCounts) {
            std::printf("%-22s %7d", r.scene.c_str(), t);
            for (const auto* set : {&r.replay.closest, &r.replay.shadow}) {
                if (set == &r.replay.shadow) std::printf(" |");
                for (const ref::ReplayRate& rate : *set)
                    if (rate.threads == t) std::printf(" %9.2f", mega(rate.raysPerSecond()));
            }
            std::printf("\n");
        }
        for (const std::string& w : r.replay.warnings)
            std::printf("  note: %s\n", w.c_str());
    }
}

void printRatioTable(const std::vector<ref::BenchSceneResult>& results) {
    std::printf("\npath tracer rate / raw Embree rate for the same ray mix (%d threads)\n",
                results.front().threads);
    std::printf("%-22s %12s %11s %11s %11s %11s %11s\n", "scene", "PT Mr/s", "vs 1", "vs 8",
                "vs 16", "vs 1M", "vs best");
    for (const ref::BenchSceneResult& r : results) {
        std::printf("%-22s %12.2f", r.scene.c_str(), mega(r.raysPerSecond()));
        double best = 0.0;
        for (const char* method : {"1", "8", "16", "1M"}) {
            const double raw = r.rawMixRaysPerSecond(method, r.threads);
            best = std::max(best, raw);
            std::printf(" %11.3f", raw > 0.0 ? r.raysPerSecond() / raw : 0.0);
        }
        std::printf(" %11.3f\n", best > 0.0 ? r.raysPerSecond() / best : 0.0);
    }
}

void printConvergenceTable(const std::vector<ref::BenchSceneResult>& results) {
    std::printf(
        "\ntime to a relative MSE of %g against a long run (other seed); extrapolated: "
        "against the exact image, from the last point\n",
        results.front().convergence.targetRelMse);
    std::printf("%-22s %9s %9s %8s %8s %9s %9s %9s %9s %11s\n", "scene", "predicted", "long spp",
                "long s", "spp", "seconds", "extr spp", "extr s", "s/spp", "efficiency");
    for (const ref::BenchSceneResult& r : results) {
        const ref::BenchConvergence& c = r.convergence;
        char spp[32] = "not", seconds[32] = "reached";
        if (c.reached) {
            std::snprintf(spp, sizeof spp, "%llu", (unsigned long long)c.samples);
            std::snprintf(seconds, sizeof seconds, "%.2f", c.seconds);
        }
        std::printf("%-22s %9llu %9llu %8.1f %8s %9s %9llu %9.1f %9.4f %11.4g\n", r.scene.c_str(),
                    (unsigned long long)c.predictedSamples, (unsigned long long)c.longSamples,
                    c.longSeconds, spp, seconds, (unsigned long long)c.extrapolatedSamples,
                    c.extrapolatedSeconds, c.secondsPerSample(), c.efficiency());
    }
}

}  // namespace

int runBenchReference(const BenchReferenceOptions& options) {
    Progress::setQuiet(options.quiet);
    std::vector<std::string> scenes = options.scenes;
    if (scenes.empty()) scenes = {"", defaultSponzaPath()};

    ref::ReferenceSettings settings;
    settings.maxBounces = options.maxBounces;
    settings.rouletteStartBounce = options.rouletteDepth;
    settings.rouletteThreshold = options.rouletteThreshold;
    settings.pixelFilter =
        options.pixelFilter == "center" ? ref::PixelFilter::Center : ref::PixelFilter::Box;
    settings.sampler =
        options.sampler == "sobol" ? ref::SamplerKind::Sobol : ref::SamplerKind::Independent;
    ref::BenchOptions bench;
    bench.spp = options.spp;
    bench.longSpp = options.longSpp;
    bench.targetRelMse = options.targetRelMse;
    bench.maxLongSeconds = options.longMaxSeconds;

    const nlohmann::ordered_json provenance = provenanceJson(options.commandLine);
    std::printf("gilab bench reference: Embree %s, %s, %u hardware threads\n", RTC_VERSION_STRING,
                provenance["cpu"].get<std::string>().c_str(),
                provenance["hardware_threads"].get<unsigned>());
    std::printf("command: %s\n", options.commandLine.c_str());

    std::vector<ref::BenchSceneResult> results;
    nlohmann::ordered_json skipped = nlohmann::ordered_json::array();
    for (const std::string& path : scenes) {
        Scene scene;
        try {
            scene = loadSceneOrDefault(path);
            applyResolutionOverride(scene, options.resolution);
        } catch (const Error& e) {
            std::printf("skipping %s: %s\n", path.c_str(), e.what());
            skipped.push_back({{"scene", path}, {"reason", e.what()}});
            continue;
        }
        results.push_back(ref::benchReferenceScene(scene, settings, bench));
    }
    if (results.empty()) {
        std::fprintf(stderr, "gilab: bench reference: no scene could be loaded\n");
        return kExitError;
    }

    printRenderTable(results);
    printReplayTable(results);
    printRatioTable(results);
    printConvergenceTable(results);

    if (!options.outDir.empty()) {
        std::filesystem::create_directories(options.outDir);
        nlohmann::ordered_json json;
        json["provenance"] = provenance;
        json["embree"] = RTC_VERSION_STRING;
        json["settings"] = {{"spp", options.spp},
                            {"max_bounces", options.maxBounces},
                            {"long_spp", options.longSpp},
                            {"long_max_seconds", options.longMaxSeconds},
                            {"target_rel_mse", options.targetRelMse},
                            {"resolution", options.resolution}};
        json["scenes"] = nlohmann::ordered_json::array();
        for (const ref::BenchSceneResult& r : results)
            json["scenes"].push_back(ref::benchSceneJson(r));
        json["skipped"] = skipped;
        const std::string path = options.outDir + "/bench_reference.json";
        writeJsonAtomic(path, json);
        std::printf("\nwrote %s\n", path.c_str());
    }
    return kExitOk;
}

}  // namespace gilab::cli
