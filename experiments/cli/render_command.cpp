// `gilab render`: one technique, one scene -> <out>/output.exr, final.png, indirect.png,
// result.json (the file names of a `gilab run` folder)
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>

#include "core/image/image_io.h"
#include "core/passes/shared_passes.h"
#include "core/scene/scene_loader.h"
#include "core/technique/frame_harness.h"
#include "core/technique/registry.h"
#include "core/util/error.h"
#include "core/util/progress.h"
#include "core/vk/check.h"
#include "core/vk/context.h"
#include "experiments/cli/cli.h"
#include "experiments/runner/run_metadata.h"
#include "experiments/runner/run_store.h"

namespace gilab::cli {

void applyAssignments(const std::vector<std::string>& assignments, ParamSet& technique,
                      ParamSet& shared) {
    std::map<std::string, std::string> seen;  // key -> its first assignment
    for (const std::string& a : assignments) {
        try {
            auto [key, value] = splitAssignment(a);
            // Two values for one key: refused, not "the last wins" silently (issue 31).
            const auto [it, first] = seen.emplace(key, a);
            if (!first)
                throw UsageError("--set " + a + ": \"" + key + "\" is already set by --set " +
                                 it->second + " (give each parameter once)");
            if (key.rfind("shared.", 0) == 0)
                shared.set(key.substr(7), value);
            else
                technique.set(key, value);
        } catch (const UsageError&) {
            throw;
        } catch (const Error& e) {
            throw UsageError("--set " + a + ": " + e.what());  // a bad command line: exit 2
        }
    }
}

namespace {

/** Prints the validation summary of a run that reported messages (they are in the sidecar). */
void reportValidation(const nlohmann::ordered_json& validation, const std::string& jsonPath) {
    if (validationMessageCount(validation) == 0) return;
    std::fprintf(stderr,
                 "gilab: invalid: %u Vulkan validation errors and %u warnings during the run "
                 "(messages in %s)\n",
                 validation["errors"].get<uint32_t>(), validation["warnings"].get<uint32_t>(),
                 jsonPath.c_str());
}

/** Adds the run's validation messages and its final status to the sidecar and writes it. */
std::string finishSidecar(vk::Context& ctx, nlohmann::ordered_json& meta,
                          const std::string& jsonPath, exp::RunOutcome outcome) {
    meta["validation"] = takeValidationJson(ctx);
    outcome.validationMessages = validationMessageCount(meta["validation"]);
    meta["status"] = exp::runStatus(outcome);
    writeJsonAtomic(jsonPath, meta);
    return meta["status"];
}

}  // namespace

int exitCodeForStatus(const std::string& status) {
    if (status == "ok") return kExitOk;
    if (status == "nonfinite") return kExitNonFinite;
    if (status == "unsupported") return kExitUnsupported;
    if (status == "invalid") return kExitInvalid;
    return kExitError;
}

int runRender(const RenderOptions& options) {
    Progress::setQuiet(options.quiet);
    Scene scene = loadSceneOrDefault(options.scenePath);
    applyResolutionOverride(scene, options.resolution);
    // `render` draws one static frame; an animated scene's sequence is `gilab run`'s (issue 31:
    // it used to render frame 0 without a word).
    if (scene.animation.animated())
        scene.warnings.push_back(
            "animated scene (" + std::to_string(scene.animation.frameCount) +
            " frames): render draws its frame 0 (t = 0) as a static frame; `gilab run` with an "
            "experiment of this scene renders the sequence and times the dynamic frames "
            "(docs/scenes.md, \"Animation\")");
    for (const std::string& w : scene.warnings)
        std::fprintf(stderr, "gilab: %s: warning: %s\n", scene.name.c_str(), w.c_str());

    const TechniqueRegistry& registry = TechniqueRegistry::instance();
    ParamSet params = registry.defaultParams(options.technique);
    ParamSet shared = defaultSharedParams();
    applyAssignments(options.assignments, params, shared);
    checkParamValues(options.technique, params, shared);  // cross-parameter rules: exit 2

    // The output folder is checked now and made only once there is something to write, so a
    // refused or failed render leaves none behind.
    const std::filesystem::path outDir(
        options.outDir.empty() ? "results/render/" + options.technique : options.outDir);
    checkOutputFolder("--out", outDir);
    const std::filesystem::path exrPath = outDir / "output.exr";
    const std::filesystem::path jsonFile = outDir / "result.json";
    if (!options.force && (std::filesystem::exists(exrPath) || std::filesystem::exists(jsonFile)))
        throw Error(outDir.string() +
                    " already holds a render (output.exr / result.json); pass --force to "
                    "overwrite it, or choose another --out");

    vk::ContextOptions ctxOptions;
    ctxOptions.validation = options.validation;
    ctxOptions.deviceFilter = options.device;
    vk::Context ctx(ctxOptions);
    const uint32_t maxSide = ctx.properties().limits.maxImageDimension2D;
    if (uint32_t(scene.settings.width) > maxSide || uint32_t(scene.settings.height) > maxSide)
        throw Error("resolution " + std::to_string(scene.settings.width) + "x" +
                    std::to_string(scene.settings.height) + " is larger than " + ctx.deviceName() +
                    " allows for an image (" + std::to_string(maxSide) +
                    " pixels a side, maxImageDimension2D); give a smaller --resolution");

    nlohmann::ordered_json meta;
    meta["status"] = "running";
    meta["provenance"] = provenanceJson(options.commandLine);
    meta["device"] = deviceJson(ctx);
    meta["scene"] = sceneToJson(scene);
    meta["technique"] = {
        {"id", options.technique},
        {"indirect_bounces", claimedBounces(registry.get(options.technique), params)},
        {"params", params.toOrderedJson()}};
    meta["shared_params"] = shared.toOrderedJson();

    const std::string jsonPath = jsonFile.string();
    // Destroyed before the validation messages are collected, so they include its teardown.
    auto harness = std::make_unique<FrameHarness>(ctx, scene, options.technique, params, shared);
    if (!harness->support().supported) {
        meta["reason"] = harness->support().reason;
        harness.reset();
        std::fprintf(stderr, "gilab: %s skipped on %s: %s\n", options.technique.c_str(),
                     scene.name.c_str(), meta["reason"].get<std::string>().c_str());
        std::filesystem::create_directories(outDir);
        const std::string status = finishSidecar(ctx, meta, jsonPath, {.supported = false});
        reportValidation(meta["validation"], jsonPath);
        return exitCodeForStatus(status);
    }

    SetupTiming setup;
    std::vector<FrameTiming> frames;
    WarmupResult warmup;
    std::vector<ImageLayer> layers;
    try {
        Progress setupProgress("set-up " + options.technique + " on " + scene.name);
        setup = harness->setup();
        setupProgress.finish();

        const int total = options.warmupFrames + options.frames;
        Progress frameProgress("frames", size_t(total));
        warmup = harness->warmUp(options.warmupFrames, [&](int i) {
            frameProgress.update(size_t(std::min(i + 1, options.warmupFrames)));
        });
        for (int i = options.warmupFrames; i < total; ++i) {
            frames.push_back(harness->renderFrame());
            frameProgress.update(size_t(i + 1));
        }
        frameProgress.finish();
        layers = harness->readLayers();
    } catch (const vk::OutOfMemoryError& e) {
        throw Error(describeOutOfMemory(scene.settings.width, scene.settings.height, e));
    }
    size_t nonFinite = 0;
    meta["nonfinite"] = finiteJson(layers, &nonFinite);
    meta["timing"] = timingJson(setup, frames, warmup);
    meta["memory"] = memoryJson(harness->memory());
    meta["skipped_passes"] = harness->skipped();
    meta["notes"] = harness->notes();
    meta["stats"] = nlohmann::ordered_json::object();
    for (const auto& [name, value] : harness->stats())
        meta["stats"][name] = value;
    harness.reset();

    std::filesystem::create_directories(outDir);
    writeExrWithMainImage(exrPath.string(), layers, "final", {{kPixelFilterAttribute, "center"}});
    ToneMap tm;
    tm.exposureEv = scene.settings.exposureEv;
    writePngTonemapped((outDir / "final.png").string(), layers.front().image, tm);
    writePngTonemapped((outDir / "indirect.png").string(), layers[1].image, tm);
    meta["outputs"] = {
        {"exr", "output.exr"}, {"final_png", "final.png"}, {"indirect_png", "indirect.png"}};
    const std::string status =
        finishSidecar(ctx, meta, jsonPath, {.supported = true, .nonFinitePixels = nonFinite});

    const auto& cpu = meta["timing"]["frame_cpu_ms"];
    const auto& gpu = meta["timing"]["frame_gpu_ms"];
    std::printf(
        "%s on %s (%dx%d, %s): set-up %.1f ms, frame %.2f ms CPU / %.2f ms GPU (median of "
        "%d)\n",
        options.technique.c_str(), scene.name.c_str(), scene.settings.width, scene.settings.height,
        ctx.deviceName().c_str(), setup.totalMs,
        cpu["median"].is_number() ? cpu["median"].get<double>() : -1.0,
        gpu["median"].is_number() ? gpu["median"].get<double>() : -1.0, options.frames);
    for (const auto& skipped : meta["skipped_passes"])
        std::printf("  skipped %s\n", skipped.get<std::string>().c_str());
    for (const auto& note : meta["notes"]) {
        const std::string n = note.get<std::string>();
        if (n.find(" lights nothing: ") != std::string::npos)
            std::fprintf(stderr, "gilab: warning: %s\n", n.c_str());
    }
    std::printf("  wrote %s/{output.exr,final.png,indirect.png,result.json}\n",
                outDir.string().c_str());
    if (nonFinite)
        std::fprintf(stderr,
                     "gilab: %zu non-finite pixels in the outputs (see \"nonfinite\" in %s)\n",
                     nonFinite, jsonPath.c_str());
    reportValidation(meta["validation"], jsonPath);
    return exitCodeForStatus(status);
}

}  // namespace gilab::cli
