#pragma once
/** The gilab command line: `gilab --help` lists the commands. */
#include <atomic>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "experiments/audit/audit.h"
#include "experiments/runner/runner.h"

#include <nlohmann/json.hpp>

#include "core/params/params.h"
#include "core/scene/scene.h"
#include "core/util/error.h"
#include "reference/reference_settings.h"

namespace gilab::vk {
class OutOfMemoryError;
}

namespace gilab::cli {

/** Exit codes, stable for scripts. */
enum ExitCode : int {
    kExitOk = 0,
    kExitError = 1,        // bad input, I/O or Vulkan failure (message on stderr)
    kExitUsage = 2,        // bad command line
    kExitUnsupported = 3,  // the technique cannot run on this scene (reason printed and saved)
    kExitNonFinite = 4,    // the run finished but an output has NaN/Inf pixels (counted, saved)
    kExitInvalid = 5,      // validation was on and reported an error or warning (messages saved)
    kExitAuditRed = 6,     // `gilab audit` found a red cell (docs/audit.md)
};

/** A bad command line (exit code 2), thrown by the commands' own argument checks. */
class UsageError : public Error {
public:
    using Error::Error;
};

/** The closest of `candidates` to `word` (edit distance), or "" when none is close. */
std::string closestMatch(const std::string& word, const std::vector<std::string>& candidates);

/** Throws UsageError (with the closest registered id) when `id` is not a technique. */
void checkTechniqueName(const std::string& id);

/** The exit code of a run with this status ("ok", "nonfinite", "unsupported", "invalid"). */
int exitCodeForStatus(const std::string& status);
/** The exit code of `gilab run` after all its runs: interrupted, then invalid, then nonfinite. */
int runExitCode(const exp::RunnerSummary& summary, bool interrupted);

int runMain(int argc, char** argv);

/** Options of `gilab render`, also used by tests. */
struct RenderOptions {
    std::string scenePath;  // "" = the built-in Cornell box; "file.json#variant" selects a variant
    std::string technique = "direct";
    std::vector<std::string> assignments;  // "key=value" or "shared.key=value"
    std::string outDir;                    // "" = results/render/<technique>
    bool force = false;                    // overwrite an existing output
    std::string resolution;                // "WxH", "" = the scene's
    int warmupFrames = 1;
    int frames = 3;
    std::string device;
    bool validation = false;
    bool quiet = false;
    std::string commandLine;
};
int runRender(const RenderOptions& options);

/** Splits --set assignments ("key=value", "shared.key=value") between the technique's and the
 *  shared passes' parameter sets; unknown keys and bad values throw gilab::Error naming them. */
void applyAssignments(const std::vector<std::string>& assignments, ParamSet& technique,
                      ParamSet& shared);

/** `gilab bench technique`: set-up and per-frame GPU times of techniques, printed as a table. */
struct BenchTechniqueOptions {
    std::string scenePath;                 // "" = the built-in Cornell box
    std::vector<std::string> techniques;   // default: every registered technique
    std::vector<std::string> assignments;  // applied to every technique (must exist in each)
    std::string resolution = "256x256";
    int warmupFrames = 1;
    int frames = 5;
    std::string device;
    bool quiet = false;
};
int runBenchTechnique(const BenchTechniqueOptions& options);

/** `gilab bench light-power`: each punctual light's emitted, incident and reflected power,
 *  traced with Embree (reference/light_power.h): what a voxel volume's lit power should be. */
struct BenchLightPowerOptions {
    std::vector<std::string> scenes;
    uint32_t rays = 1u << 20;  // per light
};
int runBenchLightPower(const BenchLightPowerOptions& options);

/** `gilab bench direct`: the shared direct light against the path tracer on every shipped scene
 *  (docs/shared_passes.md, "Accuracy"). */
struct BenchDirectOptions {
    std::vector<std::string> scenes;       // default: scenes/*.json, scenes/stress/*.json, variants
    std::vector<std::string> assignments;  // shared.key=value (the direct pass's settings)
    std::string resolution;                // "WxH", "" = each scene's
    uint64_t areaSpp = 1024;               // reference samples where emitters light the scene
    int frames = 5;                        // timed frames after one warm-up
    std::string cacheDir;
    bool noCache = false;
    std::string device;
    std::string outDir;  // "" = print only
    bool quiet = false;
    std::string commandLine;
    uint32_t placements = 0;     // > 0: random point/spot placements per scene file instead
    uint32_t placementSeed = 1;  // light_placements.h
};
int runBenchDirect(const BenchDirectOptions& options);

/** `gilab bench rt`: the GPU ray tracer (core/rt) against Embree, random rays on every shipped
 *  scene (reference/rt_validation.h, docs/gpu_rays.md); exit 1 when a scene breaks the rules. */
struct BenchRtOptions {
    std::vector<std::string> scenes;  // default: the built-in Cornell box and scenes/*.json
    uint64_t rays = 1'000'000;        // per scene
    uint64_t seed = 1;
    std::string outPath;  // "" = print only
    std::string device;
    bool validation = false;
    bool quiet = false;
    std::string commandLine;
};
int runBenchRt(const BenchRtOptions& options);

/** Options of `gilab reference` (docs/reference_cache.md), also used by tests. */
struct ReferenceOptions {
    std::string scenePath;  // "" = the built-in Cornell box
    uint64_t spp = 0;       // stop criteria: whichever comes first; none set = 64 spp
    double relError = 0.0;
    double seconds = 0.0;
    int maxBounces = 32;
    int rouletteDepth = ref::ReferenceSettings{}.rouletteStartBounce;
    float rouletteThreshold = ref::ReferenceSettings{}.rouletteThreshold;
    std::string estimator = "mis";        // mis | nee | bsdf
    std::string pixelFilter = "center";   // "center" (the rasteriser's footprint) | "box"
    std::string sampler = ref::samplerKindName(ref::ReferenceSettings{}.sampler);  // or "independent"
    uint32_t sobolReplicate = ref::ReferenceSettings{}.sobolReplicate;
    uint64_t seed = 1;
    uint32_t batchSamples = ref::ReferenceSettings{}.batchSamples;
    std::string frames;      // animated scenes: "all", "every:K", "0,4,8"; "" = static
    std::string resolution;  // "WxH", "" = the scene's
    std::string cacheDir;    // "" = $GILAB_REFERENCE_CACHE or results/cache/reference
    bool noCache = false;
    std::string outDir = "results/reference";
    std::string longReference;  // EXR of a longer run: adds the MSE-vs-samples curve
    bool quiet = false;
    std::string commandLine;
    /** Cancel flag (tests); null = Ctrl-C (SIGINT) or SIGTERM cancels, a second one kills. */
    const std::atomic<bool>* cancel = nullptr;
};
int runReference(const ReferenceOptions& options);

/** Options of `gilab bench reference`. */
struct BenchReferenceOptions {
    std::vector<std::string> scenes;  // empty = built-in Cornell box and scenes/sponza.json
    uint64_t spp = 16;                // samples of the timed render
    std::string resolution;           // "WxH", "" = each scene's
    uint64_t longSpp = 0;             // long run for the convergence figure; 0 = automatic
    double longMaxSeconds = 120.0;    // cap of the long run (and of the run measured against it)
    double targetRelMse = 1e-3;
    int maxBounces = 32;
    int rouletteDepth = ref::ReferenceSettings{}.rouletteStartBounce;
    float rouletteThreshold = ref::ReferenceSettings{}.rouletteThreshold;
    std::string pixelFilter = "box";      // "box" | "center"
    std::string sampler = ref::samplerKindName(ref::ReferenceSettings{}.sampler);  // or "independent"
    std::string outDir;                   // "" = print only
    bool quiet = false;
    std::string commandLine;
};
int runBenchReference(const BenchReferenceOptions& options);

/** `gilab audit`; see experiments/audit/audit.h. Exit 6 on any red cell, 130 interrupted. */
int runAuditCommand(audit::AuditOptions options);

/** `gilab run CONFIG`; see experiments/runner/runner.h. */
int runExperimentCommand(const exp::RunnerOptions& options);
/** `gilab report DIR...`: runs `python3 -m gilab_report` (Debian's python3) with the package's
 * folder on PYTHONPATH. */
int runReport(const std::vector<std::string>& dirs, const std::string& outDir);

/** `gilab slurm CONFIG`: see experiments/cli/slurm_command.cpp and docs/cluster.md. */
struct SlurmOptions {
    std::string configPath;
    int shards = 4;
    int referenceShards = 0;  // 0 = one per reference, at most `shards`
    std::string partition;
    std::string time;
    std::string gres;
    int cpusPerTask = 2;
    std::vector<std::string> sbatchArgs;
    std::string outRoot = "results";
    std::string referenceCacheDir;  // "" = ReferenceCache::defaultDir()
    bool dryRun = false;
    std::string commandLine;
};
int runSlurm(const SlurmOptions& options);

int runList(bool json);
int runDevices(const std::string& device);
int runSceneInfo(const std::string& scenePath, bool json);

// Helpers shared by the commands (command_checks.cpp)
/** The shared passes' and the technique's cross-parameter checks (sharedSettingsFromParams,
 *  TechniqueInfo::checkParams), before any work; a failure is a UsageError (exit 2). */
void checkParamValues(const std::string& techniqueId, const ParamSet& technique,
                      const ParamSet& shared);
/** Throws UsageError when `dir` cannot become an output folder because it, or a folder above it,
 *  is a file ("cannot write to a/b (--out): a is a file, not a folder"). Creates nothing. */
void checkOutputFolder(const std::string& option, const std::filesystem::path& dir);
/** Remembers argv[0] (runMain) for runnableGilab(). */
void setInvocation(const std::string& argv0);
/** How to run the binary invoked as `argv0` from `cwd`, for hints a user pastes: "gilab" when
 *  found on PATH (no '/'), "build/gilab" when under cwd, else the absolute path; shell-quoted
 *  when needed. */
std::string runnableCommandPath(const std::string& argv0, const std::filesystem::path& cwd);
/** `text` as one word for a POSIX shell: as is when safe, else in single quotes. */
std::string quoteForShell(const std::string& text);
/** runnableCommandPath of this process ("gilab" when setInvocation was not called). */
std::string runnableGilab();
/** The error of a render that ran out of memory: the resolution, the resource and its size,
 *  and the advice to lower --resolution. */
std::string describeOutOfMemory(int width, int height, const vk::OutOfMemoryError& e);

/** Sets the scene resolution from "WxH" ("" = keep); throws gilab::Error on bad text. */
void applyResolutionOverride(Scene& scene, const std::string& text);
/** Writes `json` (2-space indent) to a temporary file, then renames it over `path`. */
void writeJsonAtomic(const std::string& path, const nlohmann::ordered_json& json);

}  // namespace gilab::cli
