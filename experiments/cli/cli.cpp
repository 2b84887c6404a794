#include "experiments/cli/cli.h"

#include "experiments/cli/compare_command.h"

#include <unistd.h>

#include <algorithm>
#include <bit>
#include <charconv>
#include <cstdio>
#include <fstream>
#include <tuple>

#include <CLI/CLI.hpp>

#include "core/technique/modules.h"
#include "core/technique/registry.h"
#include "core/util/atomic_file.h"
#include "core/util/build_info.h"
#include "core/util/error.h"

namespace gilab::cli {

namespace {

constexpr const char* kSceneHelp =
    "Scene: a description (.json, optionally #variant), a glTF file (.gltf/.glb) or builtin; "
    "default: the built-in Cornell box (docs/scenes.md)";

size_t editDistance(const std::string& a, const std::string& b) {
    std::vector<size_t> row(b.size() + 1);
    for (size_t j = 0; j <= b.size(); ++j)
        row[j] = j;
    for (size_t i = 1; i <= a.size(); ++i) {
        size_t diagonal = row[0];
        row[0] = i;
        for (size_t j = 1; j <= b.size(); ++j) {
            const size_t up = row[j];
            row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] != b[j - 1])});
            diagonal = up;
        }
    }
    return row[b.size()];
}

/** A positive integer that is a power of two (--sobol-replicate). */
const CLI::Validator kPowerOfTwo(
    [](std::string& text) -> std::string {
        unsigned long long v = 0;
        const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
        if (ec != std::errc() || end != text.data() + text.size() || !std::has_single_bit(v))
            return "must be a power of two (1, 2, 4, ...), got " + text;
        return "";
    },
    "POWER OF TWO");

/** Every long option name ("--out") of a command. */
std::vector<std::string> optionNames(const CLI::App* app) {
    std::vector<std::string> names;
    for (const CLI::Option* o : app->get_options())
        for (const std::string& n : o->get_lnames())
            names.push_back("--" + n);
    return names;
}

/**
 * For an unknown command or option on the command line, prints "unknown ...; did you mean
 * ...?" and returns true; false when the parse error is something else.
 */
bool printSuggestion(const CLI::App& app, int argc, char** argv) {
    std::vector<std::string> commands;
    for (const CLI::App* sub : app.get_subcommands({}))
        commands.push_back(sub->get_name());
    if (argc < 2) return false;
    const std::string first = argv[1];
    if (first.empty() || first[0] == '-') return false;
    const auto known = std::find(commands.begin(), commands.end(), first);
    if (known == commands.end()) {
        const std::string near = closestMatch(first, commands);
        std::fprintf(stderr,
                     "gilab: error: unknown command '%s'%s\nRun '%s --help' for the list.\n",
                     first.c_str(), near.empty() ? "" : ("; did you mean '" + near + "'?").c_str(),
                     runnableGilab().c_str());
        return true;
    }
    // Options of the command and of its sub-commands (bench reference, bench technique).
    const CLI::App* command = app.get_subcommand(first);
    std::vector<std::string> names = optionNames(command);
    std::string where = first;
    if (argc >= 3) {
        for (const CLI::App* sub : command->get_subcommands({}))
            if (sub->get_name() == argv[2]) {
                names = optionNames(sub);
                where += " " + sub->get_name();
            }
    }
    for (int i = 2; i < argc; ++i) {
        std::string arg = argv[i];
        if (arg.rfind("--", 0) != 0) continue;
        arg = arg.substr(0, arg.find('='));
        if (std::find(names.begin(), names.end(), arg) != names.end()) continue;
        const std::string near = closestMatch(arg, names);
        std::fprintf(stderr,
                     "gilab: error: unknown option '%s' for 'gilab %s'%s\nRun '%s %s --help' "
                     "for its options.\n",
                     arg.c_str(), where.c_str(),
                     near.empty() ? "" : ("; did you mean '" + near + "'?").c_str(),
                     runnableGilab().c_str(), where.c_str());
        return true;
    }
    return false;
}

/** Loads the technique modules and passes --technique-dir on to child gilab processes (the audit,
 *  slurm) through GILAB_TECHNIQUE_PATH. */
void loadModules(const std::vector<std::string>& dirs) {
    if (!dirs.empty()) {
        std::string path;
        for (const std::string& d : dirs)
            path += (path.empty() ? "" : ":") + std::filesystem::absolute(d).string();
        if (const char* old = std::getenv("GILAB_TECHNIQUE_PATH"); old && *old)
            path += std::string(":") + old;
        ::setenv("GILAB_TECHNIQUE_PATH", path.c_str(), 1);
    }
    loadTechniqueModules(moduleSearch({}));
}

}  // namespace

void checkTechniqueName(const std::string& id) {
    const TechniqueRegistry& registry = TechniqueRegistry::instance();
    if (registry.find(id)) return;
    std::vector<std::string> ids;
    for (const TechniqueInfo* info : registry.list())
        ids.push_back(info->id);
    const std::string near = closestMatch(id, ids);
    std::string known;
    for (const std::string& k : ids)
        known += (known.empty() ? "" : ", ") + k;
    throw UsageError("unknown technique \"" + id + "\"" +
                     (near.empty() ? "" : "; did you mean \"" + near + "\"?") + " (known: " +
                     known + "; `" + runnableGilab() + " list` shows their parameters)");
}

std::string closestMatch(const std::string& word, const std::vector<std::string>& candidates) {
    std::string best;
    size_t bestDistance = std::max<size_t>(2, word.size() / 3) + 1;
    for (const std::string& c : candidates) {
        const size_t d = editDistance(word, c);
        if (d < bestDistance) {
            bestDistance = d;
            best = c;
        }
    }
    return best;
}

int runMain(int argc, char** argv) {
    if (argc > 0) setInvocation(argv[0]);
    CLI::App app{
        "gilab: real-time global illumination techniques side by side on one Vulkan backend,\n"
        "measured against a path-traced ground truth."};
    app.require_subcommand(1);
    app.set_help_all_flag("--help-all", "Help for every command");
    app.set_version_flag("--version", std::string("gilab ") + build::kVersion + " (" +
                                          build::kGitCommit + ", " + build::kBuildType + ")");
    app.footer(
        "Documentation: docs/ (start with docs/tutorial.md). Exit codes: 0 ok, 1 error, "
        "2 usage, 3 unsupported, 4 non-finite pixels, 5 validation messages, 6 audit found a "
        "red cell, 130 interrupted.");

    std::string commandLine;
    for (int i = 0; i < argc; ++i)
        commandLine += (i ? " " : "") + std::string(argv[i]);

    // Technique modules (core/technique/modules.h): loaded after parsing, before any command.
    std::vector<std::string> techniqueDirs;
    app.add_option("--technique-dir", techniqueDirs,
                   "Load technique modules (gilab-technique-<id>.so) from this folder or file; "
                   "repeatable. Also searched: GILAB_TECHNIQUE_PATH (':'-separated) and "
                   "<binary dir>/../<libdir>/gilab/techniques (docs/architecture.md)");

    bool listJson = false;
    CLI::App* list = app.add_subcommand("list", "List techniques and their parameters");
    list->add_flag("--json", listJson, "Machine-readable output");

    std::string deviceFilter;
    CLI::App* devices =
        app.add_subcommand("devices", "List Vulkan devices and why each is chosen or rejected");
    devices->add_option("--device", deviceFilter, "Device name substring or index");

    std::string infoScene;
    bool infoJson = false;
    CLI::App* info = app.add_subcommand("scene-info", "Load a scene and print what it contains");
    info->add_option("--scene", infoScene, kSceneHelp);
    info->add_flag("--json", infoJson, "Machine-readable output");

    RenderOptions render;
    render.commandLine = commandLine;
    CLI::App* rend = app.add_subcommand(
        "render", "Render one technique on one scene: EXR layers, PNG preview, JSON sidecar");
    rend->add_option("--scene", render.scenePath, kSceneHelp);
    rend->add_option("--technique,-t", render.technique, "Technique id (see `gilab list`)")
        ->capture_default_str();
    rend->add_option("--set", render.assignments,
                     "Parameter key=value (technique) or shared.key=value (shared passes); "
                     "repeatable");
    rend->add_option("--out,-o", render.outDir,
                     "Output folder (default: results/render/<technique>); gets output.exr, "
                     "final.png, indirect.png, result.json as a run folder");
    rend->add_flag("--force", render.force, "Overwrite an existing render in the output folder");
    rend->add_option("--resolution", render.resolution, "Override the scene resolution, WxH");
    rend->add_option("--warmup", render.warmupFrames, "Warm-up frames (not timed)")
        ->check(CLI::Range(0, 1000))
        ->capture_default_str();
    rend->add_option("--frames", render.frames, "Timed frames")
        ->check(CLI::Range(1, 100000))
        ->capture_default_str();
    rend->add_option("--device", render.device, "Vulkan device name substring or index");
    rend->add_flag("--validation", render.validation,
                   "Enable Vulkan validation layers (any message: status invalid, exit code 5)");
    rend->add_flag("--quiet,-q", render.quiet, "No progress lines");

    ReferenceOptions reference;
    reference.commandLine = commandLine;
    CLI::App* ref = app.add_subcommand(
        "reference",
        "Path-trace the ground truth (cached): EXR mean + stderr layers, PNG, JSON sidecar");
    ref->add_option("--scene", reference.scenePath, kSceneHelp);
    ref->add_option("--spp", reference.spp, "Stop at this many samples per pixel")
        ->check(CLI::Range(uint64_t(1), uint64_t(1) << 40));
    ref->add_option("--rel-error", reference.relError,
                    "Stop when the mean relative standard error of `full` is below this")
        ->check(CLI::Range(1e-9, 10.0));
    ref->add_option("--time", reference.seconds, "Stop after this many seconds of rendering")
        ->check(CLI::Range(1e-3, 1e9));
    ref->add_option("--max-bounces", reference.maxBounces, "Indirect bounces (0 = direct only)")
        ->check(CLI::Range(0, 1024))
        ->capture_default_str();
    ref->add_option("--roulette-depth", reference.rouletteDepth,
                    "Russian roulette on paths past this bounce; -1 = off")
        ->check(CLI::Range(-1, 1024))
        ->capture_default_str();
    ref->add_option("--roulette-threshold", reference.rouletteThreshold,
                    "Roulette survival probability min(1, max(throughput) / this)")
        ->check(CLI::Range(1e-6f, 1.0f))
        ->capture_default_str();
    ref->add_option("--estimator", reference.estimator, "Light estimator")
        ->check(CLI::IsMember({"mis", "nee", "bsdf"}))
        ->capture_default_str();
    ref->add_option("--seed", reference.seed, "Random seed")->capture_default_str();
    ref->add_option("--pixel-filter", reference.pixelFilter,
                    "center: the rasteriser's footprint (rays through the pixel centre, camera-hit "
                    "textures at its mip level); box: rays over the whole pixel (antialiased)")
        ->check(CLI::IsMember({"box", "center"}))
        ->capture_default_str();
    ref->add_option("--sampler", reference.sampler,
                    "independent: i.i.d. uniforms (exact per-pixel error bars); sobol: "
                    "Owen-scrambled Sobol in scrambled replicates (error bars from their spread)")
        ->check(CLI::IsMember({"independent", "sobol"}))
        ->capture_default_str();
    ref->add_option("--sobol-replicate", reference.sobolReplicate,
                    "Sobol: samples per independently scrambled replicate, a power of two (the "
                    "replicates' spread gives the error bars)")
        ->check(CLI::Range(1u, 1u << 30) & kPowerOfTwo)
        ->capture_default_str();
    ref->add_option("--batch", reference.batchSamples,
                    "Samples per pass (stop criteria are checked between passes; no effect on "
                    "the image)")
        ->check(CLI::Range(1u, 65536u))
        ->capture_default_str();
    ref->add_option("--resolution", reference.resolution, "Override the scene resolution, WxH");
    ref->add_option("--frames", reference.frames,
                    "Animated scenes: render these frames (all, every:K, or 0,4,8), each cached "
                    "under its own key, into <out>/frame_NNN/");
    CLI::Option* cacheOpt = ref->add_option(
        "--cache", reference.cacheDir,
        "Reference cache folder (default: $GILAB_CACHE/reference, else results/cache/reference; "
        "docs/reference_cache.md)");
    ref->add_flag("--no-cache", reference.noCache, "Neither read nor write the cache")
        ->excludes(cacheOpt);
    ref->add_option("--out,-o", reference.outDir, "Output folder")->required();
    ref->add_option("--long-reference", reference.longReference,
                    "EXR of a longer render: adds the relative-MSE-vs-samples curve")
        ->check(CLI::ExistingFile);
    ref->add_flag("--quiet,-q", reference.quiet, "No progress lines");

    BenchReferenceOptions benchRef;
    benchRef.commandLine = commandLine;
    CLI::App* bench = app.add_subcommand("bench", "Benchmarks that print figures");
    bench->require_subcommand(1);
    CLI::App* benchRefCmd = bench->add_subcommand(
        "reference", "Path tracer ray rates vs raw Embree, and time to a relative MSE of 1e-3");
    benchRefCmd->add_option(
        "--scene", benchRef.scenes,
        "Scene (repeatable); default: built-in Cornell box and scenes/sponza.json");
    benchRefCmd->add_option("--spp", benchRef.spp, "Samples per pixel of the timed render")
        ->check(CLI::Range(uint64_t(1), uint64_t(1) << 20))
        ->capture_default_str();
    benchRefCmd->add_option("--resolution", benchRef.resolution, "Override the resolution, WxH");
    benchRefCmd
        ->add_option("--long-spp", benchRef.longSpp,
                     "Samples of the long run for the convergence figure (0 = 8x the estimated "
                     "samples needed)")
        ->capture_default_str();
    benchRefCmd
        ->add_option("--long-max-seconds", benchRef.longMaxSeconds,
                     "Time cap of the long run and of the run measured against it")
        ->check(CLI::Range(0.1, 1e6))
        ->capture_default_str();
    benchRefCmd->add_option("--target-rel-mse", benchRef.targetRelMse, "Convergence target")
        ->check(CLI::Range(1e-9, 1.0))
        ->capture_default_str();
    benchRefCmd->add_option("--max-bounces", benchRef.maxBounces, "Indirect bounces")
        ->check(CLI::Range(0, 1024))
        ->capture_default_str();
    benchRefCmd
        ->add_option("--roulette-depth", benchRef.rouletteDepth,
                     "Russian roulette on paths past this bounce; -1 = off")
        ->check(CLI::Range(-1, 1024))
        ->capture_default_str();
    benchRefCmd
        ->add_option("--roulette-threshold", benchRef.rouletteThreshold,
                     "Roulette survival probability min(1, max(throughput) / this)")
        ->check(CLI::Range(1e-6f, 1.0f))
        ->capture_default_str();
    benchRefCmd
        ->add_option("--pixel-filter", benchRef.pixelFilter,
                     "box: rays over the whole pixel; center: through the pixel centre")
        ->check(CLI::IsMember({"box", "center"}))
        ->capture_default_str();
    benchRefCmd
        ->add_option("--sampler", benchRef.sampler, "independent or sobol (docs/reference.md)")
        ->check(CLI::IsMember({"independent", "sobol"}))
        ->capture_default_str();
    benchRefCmd->add_option("--out,-o", benchRef.outDir, "Also write bench_reference.json here");
    benchRefCmd->add_flag("--quiet,-q", benchRef.quiet, "No progress lines");

    BenchTechniqueOptions benchTech;
    CLI::App* benchTechCmd = bench->add_subcommand(
        "technique", "Set-up and per-frame GPU times per pass of techniques (median, IQR)");
    benchTechCmd->add_option("--scene", benchTech.scenePath, kSceneHelp);
    benchTechCmd->add_option("--technique,-t", benchTech.techniques,
                             "Technique (repeatable); default: every registered technique");
    benchTechCmd->add_option("--set", benchTech.assignments,
                             "key=value for every technique, or shared.key=value (repeatable)");
    benchTechCmd->add_option("--resolution", benchTech.resolution, "WxH")->capture_default_str();
    benchTechCmd->add_option("--warmup", benchTech.warmupFrames, "Frames discarded first")
        ->check(CLI::Range(0, 1000))
        ->capture_default_str();
    benchTechCmd->add_option("--frames", benchTech.frames, "Timed frames")
        ->check(CLI::Range(1, 100000))
        ->capture_default_str();
    benchTechCmd->add_option("--device", benchTech.device, "Vulkan device name substring or index");
    benchTechCmd->add_flag("--quiet,-q", benchTech.quiet, "No progress lines");

    BenchDirectOptions benchDirect;
    benchDirect.commandLine = commandLine;
    CLI::App* benchDirectCmd = bench->add_subcommand(
        "direct",
        "The shared direct light against the path tracer on every shipped scene: energy, light "
        "leaked into shadowed pixels, HDR-FLIP, frame cost");
    benchDirectCmd->add_option("--scene", benchDirect.scenes,
                               "Scene (repeatable); default: every scenes/*.json and "
                               "scenes/stress/*.json with each of its variants");
    benchDirectCmd->add_option("--set", benchDirect.assignments,
                               "shared.key=value for the shared passes (repeatable)");
    benchDirectCmd->add_option("--resolution", benchDirect.resolution,
                               "WxH; default: each scene's");
    benchDirectCmd
        ->add_option("--area-spp", benchDirect.areaSpp,
                     "Reference samples per pixel where emitters light the scene (delta lights "
                     "need one)")
        ->check(CLI::Range(uint64_t(1), uint64_t(1) << 30))
        ->capture_default_str();
    benchDirectCmd->add_option("--frames", benchDirect.frames, "Timed frames")
        ->check(CLI::Range(1, 100000))
        ->capture_default_str();
    benchDirectCmd->add_option("--cache", benchDirect.cacheDir, "Reference cache folder")
        ->excludes(benchDirectCmd->add_flag("--no-cache", benchDirect.noCache,
                                            "Neither read nor write the cache"));
    benchDirectCmd->add_option("--device", benchDirect.device,
                               "Vulkan device name substring or index");
    benchDirectCmd
        ->add_option("--placements", benchDirect.placements,
                     "Random point and spot light placements per scene file (base variant, its "
                     "lights and emitters replaced; near walls and in corners included) instead "
                     "of the shipped lights; prints leak median / p95 and energy per scene")
        ->check(CLI::Range(0u, 10000u));
    benchDirectCmd->add_option("--seed", benchDirect.placementSeed, "Seed of --placements")
        ->capture_default_str();
    benchDirectCmd->add_option("--out,-o", benchDirect.outDir, "Also write bench_direct.json here");
    benchDirectCmd->add_flag("--quiet,-q", benchDirect.quiet, "No progress lines");

    BenchRtOptions benchRt;
    benchRt.commandLine = commandLine;
    CLI::App* benchRtCmd = bench->add_subcommand(
        "rt",
        "The GPU ray tracer against Embree on every shipped scene: closest hits and occlusion of "
        "random rays, checked against the agreement rules (docs/gpu_rays.md)");
    benchRtCmd->add_option("--scene", benchRt.scenes,
                           "Scene (repeatable); default: builtin and scenes/*.json");
    benchRtCmd->add_option("--rays", benchRt.rays, "Rays per scene")
        ->check(CLI::Range(uint64_t(1), uint64_t(1) << 30))
        ->capture_default_str();
    benchRtCmd->add_option("--seed", benchRt.seed, "Seed of the rays")->capture_default_str();
    benchRtCmd->add_option("--out,-o", benchRt.outPath, "Also write the results to this JSON file");
    benchRtCmd->add_option("--device", benchRt.device, "Vulkan device name substring or index");
    benchRtCmd->add_flag("--validation", benchRt.validation,
                         "Enable Vulkan validation layers (any message: exit code 5)");
    benchRtCmd->add_flag("--quiet,-q", benchRt.quiet, "No progress lines");

    BenchLightPowerOptions benchPower;
    CLI::App* benchPowerCmd = bench->add_subcommand(
        "light-power",
        "Each punctual light's emitted, incident and reflected power (albedo x flux at the first "
        "hit), traced with Embree: what vct's photons and cvgi's lit voxels should hold");
    benchPowerCmd->add_option("--scene", benchPower.scenes, "Scene (repeatable)")->required();
    benchPowerCmd->add_option("--rays", benchPower.rays, "Rays per light")
        ->check(CLI::Range(1u, 1u << 30))
        ->capture_default_str();

    exp::RunnerOptions run;
    run.commandLine = commandLine;
    std::string shard;
    CLI::App* runCmd = app.add_subcommand(
        "run", "Run an experiment config: every scene x technique x sweep point vs the reference");
    runCmd->add_option("config", run.configPath, "Experiment config (.json)")
        ->required()
        ->check(CLI::ExistingFile);
    runCmd->add_option("--out,-o", run.outRoot, "Results root; runs go to <out>/<experiment>/")
        ->capture_default_str();
    runCmd->add_option("--shard", shard, "Run only the slice i/N (runs whose index % N == i)");
    runCmd->add_option("--reference-cache", run.referenceCacheDir,
                       "Reference cache folder (default: $GILAB_CACHE/reference, else "
                       "results/cache/reference; docs/reference_cache.md)");
    runCmd->add_option("--device", run.device, "Vulkan device name substring or index");
    runCmd->add_flag("--validation", run.validation,
                     "Enable Vulkan validation layers (any message: the run is invalid, exit "
                     "code 5 at the end)");
    runCmd->add_flag("--dry-run", run.dryRun, "List the runs and which are finished; run nothing");
    runCmd->add_flag("--references-only", run.referencesOnly,
                     "Render (or find in the cache) the config's distinct references, sharded "
                     "by reference with --shard; no runs, no Vulkan device (docs/cluster.md)");
    runCmd->add_flag("--quiet,-q", run.quiet, "No progress lines");

    audit::AuditOptions auditOptions;
    auditOptions.commandLine = commandLine;
    bool auditNoValidation = false;
    CLI::App* auditCmd = app.add_subcommand(
        "audit",
        "Every technique and the path tracer on stiff and extreme cases: a green/amber/red "
        "stability table (docs/audit.md)");
    auditCmd
        ->add_option("--techniques", auditOptions.techniques,
                     "Techniques (comma-separated); default: every registered technique")
        ->delimiter(',');
    auditCmd
        ->add_option(
            "--cases", auditOptions.cases,
            "Cases (comma-separated) of the catalog; default: all (--quick: the quick ones)")
        ->delimiter(',');
    auditCmd->add_flag("--quick", auditOptions.quick,
                       "The reduced audit of ctest: quick cases at the quick profile's resolution");
    auditCmd->add_option("--out,-o", auditOptions.outDir, "Output folder")->capture_default_str();
    auditCmd->add_option(
        "--catalog", auditOptions.catalogPath,
        "Case catalog (default: experiments/configs/audit.json of the source tree)");
    auditCmd->add_option("--reference-cache", auditOptions.referenceCache,
                         "Reference cache folder (default: <out>/cache)");
    auditCmd->add_option("--device", auditOptions.device, "Vulkan device name substring or index");
    auditCmd->add_flag(
        "--no-validation", auditNoValidation,
        "Run without the Vulkan validation layers (default: on; any message is red)");
    auditCmd->add_flag("--quiet,-q", auditOptions.quiet, "No progress lines");

    SlurmOptions slurm;
    slurm.commandLine = commandLine;
    CLI::App* slurmCmd = app.add_subcommand(
        "slurm",
        "Submit an experiment to Slurm: a job array rendering each reference once, a job array "
        "of `gilab run --shard i/N`, then `gilab report` (docs/cluster.md)");
    slurmCmd->add_option("config", slurm.configPath, "Experiment config (.json)")
        ->required()
        ->check(CLI::ExistingFile);
    slurmCmd->add_option("--shards", slurm.shards, "Array tasks running the runs")
        ->capture_default_str()
        ->check(CLI::Range(1, 100000));
    slurmCmd
        ->add_option("--reference-shards", slurm.referenceShards,
                     "Array tasks rendering references (default: one per reference, at most "
                     "--shards)")
        ->check(CLI::Range(1, 100000));
    slurmCmd->add_option("--partition,-p", slurm.partition, "sbatch --partition");
    slurmCmd->add_option("--time,-t", slurm.time, "sbatch --time of each task, e.g. 02:00:00");
    slurmCmd->add_option("--gres", slurm.gres,
                         "sbatch --gres for the run tasks, e.g. gpu:1 (each task then uses the "
                         "Vulkan device of CUDA_VISIBLE_DEVICES; without it: lavapipe)");
    slurmCmd->add_option("--cpus-per-task,-c", slurm.cpusPerTask, "sbatch --cpus-per-task")
        ->capture_default_str()
        ->check(CLI::Range(1, 4096));
    slurmCmd->add_option("--sbatch-arg", slurm.sbatchArgs,
                         "Another sbatch option for every job, e.g. --sbatch-arg=--account=X "
                         "(repeatable)");
    slurmCmd->add_option("--out,-o", slurm.outRoot, "Results root (on the shared file system)")
        ->capture_default_str();
    slurmCmd->add_option("--reference-cache", slurm.referenceCacheDir,
                         "Reference cache on the shared file system (default: as gilab run)");
    slurmCmd->add_flag("--dry-run", slurm.dryRun, "Print the sbatch scripts; submit nothing");

    std::vector<std::string> reportDirs;
    std::string reportOut;
    CLI::App* reportCmd = app.add_subcommand(
        "report", "Write report.html (+ figures/*.svg) from results folders (shards are merged)");
    reportCmd->add_option("dirs", reportDirs, "Results folder(s), e.g. results/default")
        ->required();
    reportCmd->add_option("--out,-o", reportOut, "Output folder (default: the first folder)");

    CompareOptions compare;
    CLI::App* compareCmd = app.add_subcommand(
        "compare", "Every metric between two images (the second is the reference); error maps");
    compareCmd->add_option("test", compare.test, "Test image: file.exr[:layer] (EXR, PNG, HDR)")
        ->required();
    compareCmd->add_option("reference", compare.reference, "Reference image: file.exr[:layer]")
        ->required();
    compareCmd
        ->add_option("--metrics", compare.metrics,
                     "Comma-separated: flip,hdr-flip,relmse,psnr,ssim (default: all)")
        ->delimiter(',');
    compareCmd->add_option("--mask", compare.mask,
                           "Mask image: pool every metric over pixels whose channel 0 > 0.5");
    compareCmd->add_option("--out,-o", compare.outDir,
                           "Also write the error maps (PNG and EXR) and compare.json here");
    compareCmd->add_option("--flip-exposure", compare.flipExposure,
                           "HDR-FLIP exposure range start:stop (stops), e.g. -4:2; default: "
                           "computed from the reference");
    compareCmd->add_option("--ppd", compare.ppd, "FLIP pixels per degree (default 67)")
        ->check(CLI::Range(1.0, 1000.0));
    compareCmd->add_flag("--json", compare.json, "Print the JSON summary instead of the table");

    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        if (e.get_exit_code() == 0) return app.exit(e) == 0 ? kExitOk : kExitUsage;  // help
        if (printSuggestion(app, argc, argv)) return kExitUsage;
        app.exit(e);
        return kExitUsage;
    }

    try {
        loadModules(techniqueDirs);
        if (*list) return runList(listJson);
        if (*devices) return runDevices(deviceFilter);
        if (*info) return runSceneInfo(infoScene, infoJson);
        if (*rend) {
            checkTechniqueName(render.technique);
            return runRender(render);
        }
        if (*ref) return runReference(reference);
        if (*benchRefCmd) return runBenchReference(benchRef);
        if (*benchDirectCmd) return runBenchDirect(benchDirect);
        if (*benchPowerCmd) return runBenchLightPower(benchPower);
        if (*benchRtCmd) return runBenchRt(benchRt);
        if (*benchTechCmd) {
            for (const std::string& t : benchTech.techniques)
                checkTechniqueName(t);
            return runBenchTechnique(benchTech);
        }
        if (*runCmd) {
            if (!shard.empty()) {
                try {
                    std::tie(run.shardIndex, run.shardCount) = exp::parseShard(shard);
                } catch (const Error& e) {
                    throw UsageError(e.what());
                }
            }
            return runExperimentCommand(run);
        }
        if (*reportCmd) return runReport(reportDirs, reportOut);
        if (*slurmCmd) return runSlurm(slurm);
        if (*auditCmd) {
            auditOptions.validation = !auditNoValidation;
            return runAuditCommand(auditOptions);
        }
        if (*compareCmd) return runCompare(compare);
    } catch (const UsageError& e) {
        std::fprintf(stderr, "gilab: error: %s\n", e.what());
        return kExitUsage;
    } catch (const Error& e) {
        std::fprintf(stderr, "gilab: error: %s\n", e.what());
        return kExitError;
    } catch (const std::filesystem::filesystem_error& e) {
        std::fprintf(stderr, "gilab: error: %s\n", e.what());
        return kExitError;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "gilab: error: %s\n", e.what());
        return kExitError;
    }
    return kExitUsage;
}

void applyResolutionOverride(Scene& scene, const std::string& text) {
    if (text.empty()) return;
    const size_t x = text.find('x');
    int w = 0, h = 0;
    const bool ok = x != std::string::npos &&
                    std::from_chars(text.data(), text.data() + x, w).ptr == text.data() + x &&
                    std::from_chars(text.data() + x + 1, text.data() + text.size(), h).ptr ==
                        text.data() + text.size();
    if (!ok || w < 1 || h < 1 || w > 16384 || h > 16384)
        throw UsageError("--resolution \"" + text + "\": expected WxH with 1 <= W, H <= 16384");
    scene.settings.width = w;
    scene.settings.height = h;
}

void writeJsonAtomic(const std::string& path, const nlohmann::ordered_json& json) {
    writeFileAtomic(path, json.dump(2) + "\n");
}

}  // namespace gilab::cli
