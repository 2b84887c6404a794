#pragma once
/**
 * `gilab run CONFIG`: expands an experiment config into runs and executes the ones not finished
 * yet (docs/experiments.md). Each run: set-up once (timed), W warm-up frames, N timed frames,
 * outputs saved, metrics against the bounce-matched reference (from the reference cache),
 * memory, skipped passes; then its folder is committed atomically and a row appended to the
 * results tables. Killing the process loses no finished run.
 */
#include <atomic>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace gilab::exp {

struct RunnerOptions {
    std::string configPath;
    std::string outRoot = "results";  // results/<experiment name>/
    int shardIndex = 0;               // --shard i/N: runs whose index % N == i
    int shardCount = 1;
    std::string device;
    bool validation = false;
    bool quiet = false;
    std::string referenceCacheDir;  // "" = ReferenceCache::defaultDir()
    bool dryRun = false;            // list the runs and whether each is done; run nothing
    /** --references-only: render (or find) the distinct references of the config, the
     *  shard's share of them (reference i of the list when i % N == shard); no run, no
     *  Vulkan device. The first step of `gilab slurm` (docs/cluster.md). */
    bool referencesOnly = false;
    std::string commandLine;
};

struct RunnerSummary {
    std::filesystem::path dir;
    size_t total = 0;    // runs in the config
    size_t inShard = 0;  // runs of this shard
    size_t alreadyFinished = 0;
    size_t ran = 0;
    size_t unsupported = 0;
    size_t nonfinite = 0;
    size_t invalid = 0;  // runs with Vulkan validation messages (stored, redone next time)
    uint32_t validationOutsideRuns = 0;  // messages before the runs (the timestamp probe)
    size_t doneElsewhere = 0;       // runs another process (shard, node) was running; waited for
    size_t rowsRepaired = 0;        // finished runs whose table row was missing (addMissingRows)
    size_t referencesTotal = 0;     // --references-only: distinct references of the config
    size_t referencesInShard = 0;   // ... of this shard
    size_t referencesRendered = 0;  // ... rendered (or continued) by this process
    bool cancelled = false;
};

/** The distinct references the runs of a config compare with, as "<scene label>" or
 *  "<scene label>@<frame>" (animation frames), in the order --references-only shards them. */
std::vector<std::string> listReferences(const std::string& configPath);

RunnerSummary runExperiment(const RunnerOptions& options,
                            const std::atomic<bool>* cancel = nullptr);

/** Parses "i/N" (0 <= i < N); throws gilab::Error otherwise. */
std::pair<int, int> parseShard(const std::string& text);

}  // namespace gilab::exp
