#pragma once
/**
 * The reference cache (docs/reference_cache.md): one folder per key (reference/scene_hash.h)
 * holding the raw accumulator, the mean + standard-error EXR and a JSON sidecar, written
 * atomically; and obtainReference(), which reuses, continues or renders a reference.
 *
 *   <cache>/<key>/accumulator.bin   header, sum and sumSq (double; with Sobol replicates also
 *                                   replicateSumSq and replicateOpen), XXH3-128 checksum
 *   <cache>/<key>/reference.exr     layers "full", ..., "full_stderr", ... (float32)
 *   <cache>/<key>/reference.json    status "complete" | "partial", samples, provenance, ...
 */
#include <atomic>
#include <chrono>
#include <filesystem>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "core/image/image.h"
#include "core/scene/scene.h"
#include "reference/path_tracer.h"

namespace gilab::ref {

/** accumulator.bin format version; bump on any layout change. */
inline constexpr uint32_t kAccumulatorFormatVersion = 1;

/** Writes `acc` (durably: fsync before returning). Throws gilab::Error naming the file. */
void writeAccumulatorFile(const std::filesystem::path& path, const Accumulator& acc);
/**
 * Reads and verifies an accumulator file: magic, format version, layer count, sizes, the file
 * length and the checksum. Any mismatch throws gilab::Error naming the file and the problem.
 */
Accumulator readAccumulatorFile(const std::filesystem::path& path);

/** One cache entry as loaded. */
struct CachedReference {
    std::filesystem::path dir;
    Accumulator acc;
    nlohmann::ordered_json sidecar;
    bool complete = false;  // sidecar status "complete"; a "partial" entry is only continued
};

class ReferenceCache {
public:
    explicit ReferenceCache(std::filesystem::path dir);

    /** $GILAB_CACHE/reference, else $GILAB_REFERENCE_CACHE (older name), else
     *  "results/cache/reference" relative to the working folder (announced when created). */
    static std::filesystem::path defaultDir();

    const std::filesystem::path& dir() const { return m_dir; }
    std::filesystem::path entryDir(const std::string& key) const;
    /** <cache>/.locks/<key>.lock: held (FileLock) by the one process rendering `key`. */
    std::filesystem::path lockPath(const std::string& key) const;

    /**
     * The entry for `key`, or nullopt when there is none. A corrupt entry (a file missing,
     * unreadable or failing its checks, or a sidecar that disagrees with the accumulator)
     * throws gilab::Error naming the file. Temporary folders are never looked at.
     */
    std::optional<CachedReference> load(const std::string& key) const;

    /**
     * Creates or replaces the entry for `key` atomically: everything is written and fsynced in
     * `<cache>/.tmp-<key>-<pid>-<n>/`, which then replaces `<key>/` by one rename. Temporary
     * folders older than a day are removed first.
     */
    void store(const std::string& key, const Accumulator& acc,
               const nlohmann::ordered_json& sidecar) const;

    /** Removes `.tmp-*` and `.old-*` folders older than `maxAge`; returns how many. */
    size_t removeStaleTemporaries(std::chrono::seconds maxAge) const;
    /** Removes every `.tmp-<key>-*` and `.old-<key>-*` folder, whatever its age: only for the
     *  holder of the key's lock, when any such folder was left by a dead process. */
    size_t removeTemporariesOf(const std::string& key) const;

private:
    std::filesystem::path m_dir;
};

struct ObtainOptions {
    const std::atomic<bool>* cancel = nullptr;  // stop at the next batch; result is "partial"
    const Image* longReference = nullptr;       // RGB full layer of a longer run (curve only)
    /** Top-level keys added to the sidecar of a new or continued entry (provenance, scene). */
    nlohmann::ordered_json sidecarExtra = nlohmann::ordered_json::object();
};

struct ReferenceResult {
    std::string key;
    Accumulator acc;
    nlohmann::ordered_json sidecar;  // as stored (or as loaded, on a hit)
    bool complete = false;
    StopReason reason = StopReason::Samples;
    bool cacheHit = false;              // reused as stored, nothing rendered
    uint64_t continuedFromSamples = 0;  // samples loaded from the cache before rendering
    uint64_t renderedSamples = 0;       // samples added by this call
    RenderReport report;                // this call's rendering (empty on a hit)
    std::vector<std::string> warnings;  // e.g. a corrupt entry that was ignored
};

/**
 * True when a complete entry with `samples` samples and relative error `relError` already
 * meets `stop`: samples >= maxSamples, or relError <= targetRelError, or any time budget.
 */
bool satisfiesStop(uint64_t samples, double relError, const StopCriteria& stop);

/**
 * The reference for (scene, settings) meeting `stop`. With a cache, the key's lock is held
 * throughout, so of several processes sharing the cache one renders and the others wait and
 * then reuse its entry (a cancel while waiting returns reason Cancelled with no samples). A
 * complete cache entry that satisfies it is returned without rendering; otherwise rendering
 * continues from the stored accumulator (samples [N, ...)) or starts from zero, and the result is
 * stored, as "partial" when cancelled. A corrupt entry is reported in `warnings` and rendered
 * again. `cache` may be null (no cache). Throws gilab::Error when no stop criterion is set.
 */
ReferenceResult obtainReference(const Scene& scene, const ReferenceSettings& settings,
                                const StopCriteria& stop, const ReferenceCache* cache,
                                const ObtainOptions& options = {});

/** {"max_samples", "target_rel_error", "max_seconds"} (0 = off). */
nlohmann::ordered_json stopCriteriaJson(const StopCriteria& stop);
// settingsJson(ReferenceSettings), the sidecar's "settings": reference/reference_settings.h.

}  // namespace gilab::ref
