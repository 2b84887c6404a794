#pragma once
/**
 * results/<experiment>/: results that are never lost.
 *
 *   runs/<key>/result.json   one folder per finished run (plus its EXR, PNGs, FLIP map)
 *   runs/.tmp-<key>-<host>-<pid>/  a run in progress; renamed to runs/<key>/ only when
 *                            complete, so a killed run never leaves a folder that looks finished
 *   runs/.locks/<key>.lock   held (flock) by the one process running <key>
 *   .locks/results.lock      held while a row is appended to the tables
 *   references/<label>/      the bounce-matched reference images each run was compared with
 *   results.jsonl            append-only table, one JSON object per finished run
 *   results.csv              the same rows as CSV (flat columns)
 * A run's key is a hash of its resolved configuration: re-running a config skips keys whose
 * folder holds a finished result.json and redoes only what changed. Any number of processes
 * (shards, nodes of a cluster) may share the folder (docs/cluster.md).
 */
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/util/atomic_file.h"
#include "core/util/file_lock.h"

namespace gilab::exp {

class RunStore {
public:
    /** Creates <experimentDir>/runs unless `create` is false (a dry run only reads). */
    explicit RunStore(std::filesystem::path experimentDir, bool create = true);

    const std::filesystem::path& dir() const { return m_dir; }
    std::filesystem::path runDir(const std::string& key) const;
    /** The status recorded in runs/<key>/result.json; "" when missing or unreadable. */
    std::string storedStatus(const std::string& key) const;
    /** True when runs/<key>/result.json exists and records a final status. */
    bool isFinished(const std::string& key) const;

    /** The run's lock if no other process holds it (FileLock::tryAcquire). */
    std::optional<FileLock> tryClaim(const std::string& key) const;
    /** Waits for the run's lock (nullopt if `cancel` became true first). */
    std::optional<FileLock> claim(const std::string& key, const std::atomic<bool>* cancel) const;

    /** A fresh temporary folder for a run. The caller holds the run's claim, so any other
     *  temporary folder of this key is left by a dead process and is removed first. */
    std::filesystem::path beginRun(const std::string& key) const;
    /** Moves the temporary folder to runs/<key>/ (atomic rename). */
    void commitRun(const std::filesystem::path& tmpDir, const std::string& key) const;

    /** Appends one row to results.jsonl (flushed and synced) and rewrites results.csv, under
     *  the tables' lock. */
    void appendRow(const nlohmann::ordered_json& row) const;
    /** Adds the row of every finished run folder that results.jsonl lacks (a process killed
     *  between committing a run and appending its row); returns how many. */
    size_t addMissingRows() const;
    /** results.csv from results.jsonl: one column per key of any row (atomic rewrite). */
    void writeCsv() const;

    /** Every stored run's result.json (final or invalid), sorted by run index then key. */
    std::vector<nlohmann::json> loadFinished() const;

private:
    std::filesystem::path m_dir;
};

/** Statuses that mark a run as done (not retried): "ok", "nonfinite", "unsupported". */
bool isFinalStatus(const std::string& status);
/** Statuses of a committed run folder: the final ones and "invalid" (kept, but redone on the
 *  next `gilab run`, so a fixed technique is measured again). */
bool isStoredStatus(const std::string& status);

/** What decides a run's status once it has been attempted. */
struct RunOutcome {
    bool supported = true;            // false: nothing was rendered (the reason is saved)
    size_t nonFinitePixels = 0;       // NaN/Inf pixels over all output layers
    uint32_t validationMessages = 0;  // Vulkan validation errors + warnings during the run
};
/**
 * "invalid" when validation reported any message (results of an invalid API use are not
 * trusted), else "unsupported", "nonfinite" or "ok".
 */
std::string runStatus(const RunOutcome& outcome);

/** Flattens nested objects to "a.b.c" columns for CSV (arrays are JSON-encoded in one cell). */
void flattenJson(const nlohmann::ordered_json& value, const std::string& prefix,
                 std::vector<std::pair<std::string, std::string>>& out);

/** A label safe as a folder name: letters, digits, '-', '_' kept; everything else -> '_'. */
std::string sanitizeLabel(const std::string& label);

/**
 * The flat row of the results tables for a run's result.json: identity, parameters (as
 * "k=v ..."), status, validation counts, set-up and frame times, memory, the headline metrics,
 * provenance.
 */
nlohmann::ordered_json resultRow(const nlohmann::ordered_json& result);

}  // namespace gilab::exp
