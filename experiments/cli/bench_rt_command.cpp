// `gilab bench rt`: the GPU ray tracer (core/rt) against Embree on every shipped scene: random
// rays traced by both for the closest hit and for occlusion, checked against the rules of
// reference/rt_validation.h (docs/gpu_rays.md). One table row per scene; exits 1 when a scene
// breaks a rule.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "core/scene/scene_loader.h"
#include "core/util/build_info.h"
#include "core/util/error.h"
#include "core/util/progress.h"
#include "core/vk/context.h"
#include "experiments/cli/cli.h"
#include "experiments/runner/run_metadata.h"
#include "reference/rt_validation.h"

namespace gilab::cli {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

/** The scene folder: ./scenes, else the source tree's. */
fs::path rtScenesDir() {
    if (fs::is_directory("scenes")) return "scenes";
    return fs::path(build::kSourceDir) / "scenes";
}

/** The built-in Cornell box, then every scenes/<name>.json (base variants: a variant changes
 * lights, not the triangles the tracer sees), sorted. */
std::vector<std::string> rtShippedScenes() {
    std::vector<std::string> out{"builtin"};
    std::vector<fs::path> files;
    for (const fs::directory_entry& e : fs::directory_iterator(rtScenesDir()))
        if (e.is_regular_file() && e.path().extension() == ".json") files.push_back(e.path());
    std::sort(files.begin(), files.end());
    for (const fs::path& f : files)
        out.push_back(f.string());
    return out;
}

Json resultJson(const std::string& spec, const ref::RtValidationResult& r) {
    auto num = [](double v) { return std::isfinite(v) ? Json(v) : Json(nullptr); };
    return Json{{"scene", spec},
                {"name", r.scene},
                {"status", r.passed() ? "passed" : "failed"},
                {"failures", r.failures()},
                {"triangles", r.triangles},
                {"diagonal", num(r.diagonal)},
                {"bvh",
                 {{"nodes", r.bvh.nodes},
                  {"leaves", r.bvh.leaves},
                  {"depth", r.bvh.depth},
                  {"triangle_refs", r.bvh.triangleRefs},
                  {"triangles", r.bvh.triangles},
                  {"degenerate_dropped", r.bvh.degenerateDropped},
                  {"build_ms", num(r.bvh.buildMs)}}},
                {"rays", r.rays},
                {"embree_hits", r.embreeHits},
                {"gpu_hits", r.gpuHits},
                {"both_hit", r.bothHit},
                {"hit_miss_disagreements", r.hitMissDisagreements},
                {"t_outliers", r.tOutliers},
                {"max_rel_t_error", num(r.maxRelTError)},
                {"max_rel_t_error_ray", r.maxRelTRay},
                {"primitive_ties", r.primitiveTies},
                {"primitive_mismatches", r.primitiveMismatches},
                {"embree_occluded", r.embreeOccluded},
                {"occlusion_disagreements", r.occlusionDisagreements},
                {"gpu_seconds", num(r.gpuSeconds)},
                {"gpu_wall_seconds", num(r.gpuWallSeconds)},
                {"gpu_rays_per_second", num(r.gpuRaysPerSecond())},
                {"gpu_wall_rays_per_second", num(r.gpuWallRaysPerSecond())},
                {"gpu_occlusion_seconds", num(r.gpuOcclusionSeconds)},
                {"gpu_occlusion_wall_seconds", num(r.gpuOcclusionWallSeconds)},
                {"embree_seconds", num(r.embreeSeconds)},
                {"embree_rays_per_second", num(r.embreeRaysPerSecond())},
                {"embree_occlusion_seconds", num(r.embreeOcclusionSeconds)},
                {"embree_build_ms", num(r.embreeBuildMs)},
                {"examples", r.examples}};
}

}  // namespace

int runBenchRt(const BenchRtOptions& options) {
    Progress::setQuiet(options.quiet);
    if (options.rays == 0) throw UsageError("--rays must be at least 1");
    const std::vector<std::string> scenes =
        options.scenes.empty() ? rtShippedScenes() : options.scenes;
    vk::ContextOptions ctxOptions;
    ctxOptions.deviceFilter = options.device;
    ctxOptions.validation = options.validation;
    vk::Context ctx(ctxOptions);

    std::printf("GPU ray tracer (core/rt) vs Embree, %s; %llu rays per scene, seed %llu\n",
                ctx.deviceName().c_str(), static_cast<unsigned long long>(options.rays),
                static_cast<unsigned long long>(options.seed));
    std::printf("%-28s %8s %8s %5s %8s %8s %7s %7s %7s %9s %6s %6s %7s %8s %8s %8s %8s  %s\n",
                "scene", "tris", "nodes", "depth", "refs", "build ms", "hit %", "hit/mis", "t out",
                "max rel t", "ties", "mism.", "occl.", "GPU s", "GPU Mr/s", "wall s", "Emb Mr/s",
                "verdict");
    Json rows = Json::array();
    int failed = 0, skipped = 0;
    for (const std::string& spec : scenes) {
        Scene scene;
        try {
            scene = loadScene(spec);
        } catch (const Error& e) {
            // A missing scene (no ../shared/scenes) is skipped when the default list was used;
            // a scene named on the command line must load.
            if (!options.scenes.empty()) throw;
            std::printf("%-28s skipped: %s\n", spec.c_str(), e.what());
            rows.push_back({{"scene", spec}, {"status", "skipped"}, {"reason", e.what()}});
            ++skipped;
            continue;
        }
        ref::RtValidationOptions vo;
        vo.rays = options.rays;
        vo.seed = options.seed;
        vo.progress = !options.quiet;
        const ref::RtValidationResult r = ref::validateGpuRayTracer(ctx, scene, vo);
        const bool ok = r.passed();
        failed += ok ? 0 : 1;
        const std::string label = spec == "builtin" ? "builtin (" + scene.name + ")" : spec;
        std::printf(
            "%-28s %8llu %8u %5u %8u %8.0f %7.2f %7llu %7llu %9.2e %6llu %6llu %7llu %8.2f %8.3f "
            "%8.2f %8.2f  %s\n",
            fs::path(label).filename().string().c_str(),
            static_cast<unsigned long long>(r.triangles), r.bvh.nodes, r.bvh.depth,
            r.bvh.triangleRefs, r.bvh.buildMs,
            r.rays > 0 ? 100.0 * double(r.embreeHits) / double(r.rays) : 0.0,
            static_cast<unsigned long long>(r.hitMissDisagreements),
            static_cast<unsigned long long>(r.tOutliers), r.maxRelTError,
            static_cast<unsigned long long>(r.primitiveTies),
            static_cast<unsigned long long>(r.primitiveMismatches),
            static_cast<unsigned long long>(r.occlusionDisagreements), r.gpuSeconds,
            1e-6 * r.gpuRaysPerSecond(), r.gpuWallSeconds, 1e-6 * r.embreeRaysPerSecond(),
            ok ? "ok" : "FAILED");
        if (!ok) {
            std::printf("%-28s   %s\n", "", r.failures().c_str());
            for (const std::string& e : r.examples)
                std::printf("%-28s   %s\n", "", e.c_str());
        }
        std::fflush(stdout);
        rows.push_back(resultJson(spec, r));
    }
    std::printf(
        "hit %%: Embree's closest-hit rays that hit; hit/mis: rays where one hits and the other "
        "misses; t out: both hit, |t_gpu - t_embree| > 1e-4 max(t, 1e-6 diagonal); ties / "
        "mism.: both hit different triangles, at the same t (coplanar, shared edge) or not; "
        "occl.: occlusion of segments disagrees; GPU s: timestamps of the closest-hit "
        "dispatches; wall s: the same traces with upload, submit and read-back; Mr/s: million "
        "closest-hit rays per second (docs/gpu_rays.md)\n");

    const uint32_t validationMessages = ctx.validationErrorCount() + ctx.validationWarningCount();
    if (!options.outPath.empty()) {
        const fs::path path(options.outPath);
        if (path.has_parent_path()) fs::create_directories(path.parent_path());
        Json out{{"device", ctx.deviceName()},
                 {"rays", options.rays},
                 {"seed", options.seed},
                 {"validation", options.validation},
                 {"validation_messages", validationMessages},
                 {"provenance", provenanceJson(options.commandLine)},
                 {"scenes", rows}};
        writeJsonAtomic(path.string(), out);
        std::printf("wrote %s\n", path.string().c_str());
    }
    if (validationMessages > 0) {
        for (const std::string& m : ctx.validationMessages())
            std::fprintf(stderr, "%s\n", m.c_str());
        std::fprintf(stderr, "gilab: invalid: %u Vulkan validation messages\n", validationMessages);
        return kExitInvalid;
    }
    if (failed > 0) {
        std::fprintf(stderr,
                     "gilab: error: the GPU ray tracer disagrees with Embree beyond the rules on "
                     "%d of %zu scenes (see the rows marked FAILED)\n",
                     failed, scenes.size() - size_t(skipped));
        return kExitError;
    }
    return kExitOk;
}

}  // namespace gilab::cli
