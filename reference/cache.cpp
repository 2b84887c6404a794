#include "reference/cache.h"

#include <fcntl.h>
#include <unistd.h>
#include <xxhash.h>

#include <bit>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <memory>

#include <embree3/rtcore_config.h>
#include <tbb/task_arena.h>

#include "core/image/image_io.h"
#include "core/util/build_info.h"
#include "core/util/error.h"
#include "core/util/file_lock.h"
#include "reference/scene_hash.h"

namespace gilab::ref {
namespace fs = std::filesystem;
namespace {

static_assert(std::endian::native == std::endian::little, "accumulator.bin is little-endian");

constexpr char kMagic[8] = {'G', 'I', 'L', 'A', 'B', 'A', 'C', 'C'};
constexpr size_t kHeaderBytes = 48;
/** Format 2 (an accumulator with Sobol replicates) adds the replicate size to the header, and
 *  the arrays replicateSumSq and replicateOpen after sumSq. Format 1 has neither. */
constexpr uint32_t kReplicateFormatVersion = 2;
constexpr size_t kReplicateHeaderBytes = 56;
constexpr size_t kChecksumBytes = 16;

struct Header {
    uint32_t version = 0;
    uint32_t layerCount = 0;
    uint32_t width = 0;
    uint32_t height = 0;
    uint64_t samples = 0;
    uint64_t nonFiniteSamples = 0;
    uint64_t valueCount = 0;  // per array (sum, sumSq)
    uint64_t replicate = 0;   // format 2
};

using FilePtr = std::unique_ptr<FILE, int (*)(FILE*)>;

std::string errnoText() {
    return std::strerror(errno);
}

/** fsync a file or folder by path; folders need it so a rename inside them is durable. */
void syncPath(const fs::path& path, bool directory) {
    const int fd = ::open(path.c_str(), O_RDONLY | (directory ? O_DIRECTORY : 0));
    if (fd < 0) throw Error(path.string() + ": cannot open to fsync: " + errnoText());
    const int rc = ::fsync(fd);
    ::close(fd);
    if (rc != 0) throw Error(path.string() + ": fsync failed: " + errnoText());
}

void writeTextSynced(const fs::path& path, const std::string& text) {
    FilePtr f(std::fopen(path.c_str(), "wb"), std::fclose);
    if (!f) throw Error(path.string() + ": cannot create: " + errnoText());
    if (std::fwrite(text.data(), 1, text.size(), f.get()) != text.size() ||
        std::fflush(f.get()) != 0 || ::fsync(fileno(f.get())) != 0)
        throw Error(path.string() + ": write failed: " + errnoText());
}

std::string readText(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error(path.string() + ": cannot read (corrupt reference cache entry)");
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

bool isHexKey(const std::string& key) {
    if (key.empty() || key.size() > 64) return false;
    for (char c : key)
        if (!((c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'))) return false;
    return true;
}

/** A name no other process or thread uses: pid + a per-process counter. */
std::string uniqueSuffix(const std::string& key) {
    static std::atomic<uint64_t> counter{0};
    return key + "-" + processTag() + "-" + std::to_string(counter++);
}

/** Atomically swaps two paths (Linux renameat2); false if the file system cannot. */
bool exchangePaths(const fs::path& a, const fs::path& b) {
#ifdef RENAME_EXCHANGE
    return ::renameat2(AT_FDCWD, a.c_str(), AT_FDCWD, b.c_str(), RENAME_EXCHANGE) == 0;
#else
    return false;
#endif
}

}  // namespace

void writeAccumulatorFile(const fs::path& path, const Accumulator& acc) {
    const uint64_t n = uint64_t(kLayerCount) * uint64_t(acc.width) * uint64_t(acc.height) * 3;
    const uint64_t replicateValues = acc.replicate > 0 ? n : 0;
    if (acc.width <= 0 || acc.height <= 0 || acc.sum.size() != n || acc.sumSq.size() != n ||
        acc.replicateSumSq.size() != replicateValues || acc.replicateOpen.size() != replicateValues)
        throw Error(path.string() + ": accumulator has inconsistent sizes, not written");
    FilePtr f(std::fopen(path.c_str(), "wb"), std::fclose);
    if (!f) throw Error(path.string() + ": cannot create: " + errnoText());

    std::unique_ptr<XXH3_state_t, XXH_errorcode (*)(XXH3_state_t*)> state(XXH3_createState(),
                                                                          XXH3_freeState);
    XXH3_128bits_reset(state.get());
    bool ok = true;
    auto put = [&](const void* data, size_t bytes) {
        XXH3_128bits_update(state.get(), data, bytes);
        ok = ok && std::fwrite(data, 1, bytes, f.get()) == bytes;
    };
    const uint32_t version =
        acc.replicate > 0 ? kReplicateFormatVersion : kAccumulatorFormatVersion;
    const uint32_t header32[4] = {version, uint32_t(kLayerCount), uint32_t(acc.width),
                                  uint32_t(acc.height)};
    const uint64_t header64[4] = {acc.samples, acc.nonFiniteSamples, n, acc.replicate};
    put(kMagic, sizeof kMagic);
    put(header32, sizeof header32);
    put(header64, acc.replicate > 0 ? 4 * sizeof(uint64_t) : 3 * sizeof(uint64_t));
    put(acc.sum.data(), n * sizeof(double));
    put(acc.sumSq.data(), n * sizeof(double));
    if (acc.replicate > 0) {
        put(acc.replicateSumSq.data(), n * sizeof(double));
        put(acc.replicateOpen.data(), n * sizeof(double));
    }
    XXH128_canonical_t digest;
    XXH128_canonicalFromHash(&digest, XXH3_128bits_digest(state.get()));
    ok = ok && std::fwrite(digest.digest, 1, sizeof digest.digest, f.get()) == kChecksumBytes;
    if (!ok || std::fflush(f.get()) != 0 || ::fsync(fileno(f.get())) != 0)
        throw Error(path.string() + ": write failed: " + errnoText());
}

Accumulator readAccumulatorFile(const fs::path& path) {
    const std::string where = path.string() + ": corrupt reference accumulator: ";
    FilePtr f(std::fopen(path.c_str(), "rb"), std::fclose);
    if (!f) throw Error(where + "cannot open: " + errnoText());
    std::error_code ec;
    const uint64_t fileBytes = fs::file_size(path, ec);
    if (ec || fileBytes < kHeaderBytes + kChecksumBytes)
        throw Error(where + "truncated (" + std::to_string(fileBytes) + " bytes)");

    unsigned char raw[kReplicateHeaderBytes];
    if (std::fread(raw, 1, kHeaderBytes, f.get()) != kHeaderBytes)
        throw Error(where + "cannot read the header");
    if (std::memcmp(raw, kMagic, sizeof kMagic) != 0) throw Error(where + "bad magic");
    Header h;
    std::memcpy(&h.version, raw + 8, 4);
    size_t headerBytes = kHeaderBytes;
    if (h.version == kReplicateFormatVersion) {
        headerBytes = kReplicateHeaderBytes;
        if (fileBytes < headerBytes + kChecksumBytes ||
            std::fread(raw + kHeaderBytes, 1, headerBytes - kHeaderBytes, f.get()) !=
                headerBytes - kHeaderBytes)
            throw Error(where + "cannot read the header");
        std::memcpy(&h.replicate, raw + 48, 8);
        if (h.replicate < 1 || h.replicate > (1u << 30) || !std::has_single_bit(h.replicate))
            throw Error(where + "bad replicate size " + std::to_string(h.replicate));
    }
    std::memcpy(&h.layerCount, raw + 12, 4);
    std::memcpy(&h.width, raw + 16, 4);
    std::memcpy(&h.height, raw + 20, 4);
    std::memcpy(&h.samples, raw + 24, 8);
    std::memcpy(&h.nonFiniteSamples, raw + 32, 8);
    std::memcpy(&h.valueCount, raw + 40, 8);
    if (h.version != kAccumulatorFormatVersion && h.version != kReplicateFormatVersion)
        throw Error(where + "format version " + std::to_string(h.version) + ", expected " +
                    std::to_string(kAccumulatorFormatVersion) + " or " +
                    std::to_string(kReplicateFormatVersion));
    if (h.layerCount != uint32_t(kLayerCount))
        throw Error(where + std::to_string(h.layerCount) + " layers, expected " +
                    std::to_string(kLayerCount));
    if (h.width < 1 || h.height < 1 || h.width > 16384 || h.height > 16384 ||
        h.valueCount != uint64_t(kLayerCount) * h.width * h.height * 3)
        throw Error(where + "bad size " + std::to_string(h.width) + "x" + std::to_string(h.height));
    const uint64_t arrays = h.replicate > 0 ? 4 : 2;
    const uint64_t expected = headerBytes + arrays * h.valueCount * sizeof(double) + kChecksumBytes;
    if (fileBytes != expected)
        throw Error(where + std::to_string(fileBytes) + " bytes, expected " +
                    std::to_string(expected) + " (truncated or extended)");

    Accumulator acc;
    acc.width = int(h.width);
    acc.height = int(h.height);
    acc.samples = h.samples;
    acc.nonFiniteSamples = h.nonFiniteSamples;
    acc.replicate = uint32_t(h.replicate);
    std::vector<double>* values[4] = {&acc.sum, &acc.sumSq, &acc.replicateSumSq,
                                      &acc.replicateOpen};
    const size_t bytes = h.valueCount * sizeof(double);
    for (uint64_t a = 0; a < arrays; ++a) {
        values[a]->resize(h.valueCount);
        if (std::fread(values[a]->data(), 1, bytes, f.get()) != bytes)
            throw Error(where + "short read");
    }
    unsigned char stored[kChecksumBytes];
    if (std::fread(stored, 1, kChecksumBytes, f.get()) != kChecksumBytes)
        throw Error(where + "short read");

    std::unique_ptr<XXH3_state_t, XXH_errorcode (*)(XXH3_state_t*)> state(XXH3_createState(),
                                                                          XXH3_freeState);
    XXH3_128bits_reset(state.get());
    XXH3_128bits_update(state.get(), raw, headerBytes);
    for (uint64_t a = 0; a < arrays; ++a)
        XXH3_128bits_update(state.get(), values[a]->data(), bytes);
    XXH128_canonical_t digest;
    XXH128_canonicalFromHash(&digest, XXH3_128bits_digest(state.get()));
    if (std::memcmp(digest.digest, stored, kChecksumBytes) != 0)
        throw Error(where + "checksum mismatch");
    return acc;
}

ReferenceCache::ReferenceCache(fs::path dir) : m_dir(std::move(dir)) {}

fs::path ReferenceCache::defaultDir() {
    // The one place that decides where references are cached (docs/reference_cache.md).
    if (const char* root = std::getenv("GILAB_CACHE"); root && *root)
        return fs::path(root) / "reference";
    if (const char* env = std::getenv("GILAB_REFERENCE_CACHE"); env && *env) return env;
    return fs::path("results/cache/reference");
}

fs::path ReferenceCache::lockPath(const std::string& key) const {
    return m_dir / ".locks" / (key + ".lock");
}

fs::path ReferenceCache::entryDir(const std::string& key) const {
    if (!isHexKey(key)) throw Error("reference cache: invalid key \"" + key + "\"");
    return m_dir / key;
}

std::optional<CachedReference> ReferenceCache::load(const std::string& key) const {
    const fs::path dir = entryDir(key);
    std::error_code ec;
    if (!fs::is_directory(dir, ec)) return std::nullopt;

    CachedReference entry;
    entry.dir = dir;
    entry.acc = readAccumulatorFile(dir / "accumulator.bin");
    const fs::path sidecarPath = dir / "reference.json";
    try {
        entry.sidecar = nlohmann::ordered_json::parse(readText(sidecarPath));
    } catch (const nlohmann::json::exception& e) {
        throw Error(sidecarPath.string() + ": corrupt reference cache sidecar: " + e.what());
    }
    const auto& s = entry.sidecar;
    const std::string where = sidecarPath.string() + ": corrupt reference cache sidecar: ";
    if (!s.is_object() || !s.contains("status") || !s["status"].is_string() ||
        !s.contains("samples") || !s["samples"].is_number_unsigned() || !s.contains("key"))
        throw Error(where + "missing \"status\", \"samples\" or \"key\"");
    if (s["key"] != key) throw Error(where + "key " + s["key"].dump() + " in folder " + key);
    if (s["samples"].get<uint64_t>() != entry.acc.samples)
        throw Error(where + "samples " + s["samples"].dump() + " but accumulator.bin has " +
                    std::to_string(entry.acc.samples));
    const std::string status = s["status"].get<std::string>();
    if (status != "complete" && status != "partial")
        throw Error(where + "status \"" + status + "\"");
    entry.complete = status == "complete";
    if (!fs::exists(dir / "reference.exr", ec))
        throw Error((dir / "reference.exr").string() + ": missing (corrupt reference cache entry)");
    return entry;
}

void ReferenceCache::store(const std::string& key, const Accumulator& acc,
                           const nlohmann::ordered_json& sidecar) const {
    const fs::path finalDir = entryDir(key);
    if (!fs::exists(m_dir)) {
        // Say so: a command run from another folder would otherwise scatter caches silently.
        std::fprintf(stderr,
                     "gilab: creating the reference cache %s (set GILAB_CACHE or pass "
                     "--cache / --reference-cache to use one cache everywhere)\n",
                     fs::absolute(m_dir).lexically_normal().string().c_str());
    }
    fs::create_directories(m_dir);
    removeStaleTemporaries(std::chrono::hours(24));

    // 1. Write and fsync every file in a private temporary folder
    const fs::path tmp = m_dir / (".tmp-" + uniqueSuffix(key));
    fs::remove_all(tmp);
    fs::create_directory(tmp);
    try {
        writeAccumulatorFile(tmp / "accumulator.bin", acc);
        std::vector<ImageLayer> layers = meanLayers(acc);
        for (ImageLayer& l : stdErrorLayers(acc))
            layers.push_back(std::move(l));
        writeExrLayers(
            (tmp / "reference.exr").string(), layers,
            {{kPixelFilterAttribute, sidecar.contains("settings")
                                         ? sidecar["settings"].value("pixel_filter", std::string())
                                         : std::string()}});
        syncPath(tmp / "reference.exr", false);
        writeTextSynced(tmp / "reference.json", sidecar.dump(2) + "\n");
        syncPath(tmp, true);

        // 2. Publish by one rename (or one exchange with the old entry), then fsync the parent
        std::error_code ec;
        if (fs::is_directory(finalDir, ec)) {
            fs::path old = tmp;  // after an exchange, tmp holds the previous entry
            if (!exchangePaths(tmp, finalDir)) {
                old = m_dir / (".old-" + uniqueSuffix(key));
                fs::rename(finalDir, old);  // a moment with no entry: a reader sees a miss
                fs::rename(tmp, finalDir);
            }
            syncPath(m_dir, true);
            fs::remove_all(old, ec);
        } else {
            fs::rename(tmp, finalDir);
            syncPath(m_dir, true);
        }
    } catch (...) {
        std::error_code ec;
        fs::remove_all(tmp, ec);
        throw;
    }
}

size_t ReferenceCache::removeStaleTemporaries(std::chrono::seconds maxAge) const {
    std::error_code ec;
    if (!fs::is_directory(m_dir, ec)) return 0;
    const auto now = fs::file_time_type::clock::now();
    size_t removed = 0;
    for (const fs::directory_entry& e : fs::directory_iterator(m_dir, ec)) {
        const std::string name = e.path().filename().string();
        if (name.rfind(".tmp-", 0) != 0 && name.rfind(".old-", 0) != 0) continue;
        const auto written = fs::last_write_time(e.path(), ec);
        if (ec || now - written < maxAge) continue;
        if (fs::remove_all(e.path(), ec) > 0 && !ec) ++removed;
    }
    return removed;
}

size_t ReferenceCache::removeTemporariesOf(const std::string& key) const {
    std::error_code ec;
    if (!fs::is_directory(m_dir, ec)) return 0;
    size_t removed = 0;
    for (const fs::directory_entry& e : fs::directory_iterator(m_dir, ec)) {
        const std::string name = e.path().filename().string();
        if (name.rfind(".tmp-" + key + "-", 0) != 0 && name.rfind(".old-" + key + "-", 0) != 0)
            continue;
        if (fs::remove_all(e.path(), ec) > 0 && !ec) ++removed;
    }
    return removed;
}

nlohmann::ordered_json stopCriteriaJson(const StopCriteria& stop) {
    return {{"max_samples", stop.maxSamples},
            {"target_rel_error", stop.targetRelError},
            {"max_seconds", stop.maxSeconds}};
}

namespace {

/** The criterion a stored entry meets (OR-ed as in renderUntil), if any. */
std::optional<StopReason> metCriterion(uint64_t samples, double relError,
                                       const StopCriteria& stop) {
    if (stop.maxSamples > 0 && samples >= stop.maxSamples) return StopReason::Samples;
    // With < 2 samples there is no error estimate
    if (stop.targetRelError > 0.0 && samples >= 2 && relError <= stop.targetRelError)
        return StopReason::RelError;
    if (stop.maxSeconds > 0.0) return StopReason::Time;  // whatever a finished render reached
    return std::nullopt;
}

}  // namespace

bool satisfiesStop(uint64_t samples, double relError, const StopCriteria& stop) {
    return metCriterion(samples, relError, stop).has_value();
}

namespace {

nlohmann::ordered_json raysJson(const RayStats& r) {
    return {{"camera", r.cameraRays},
            {"bounce", r.bounceRays},
            {"shadow", r.shadowRays},
            {"seconds", r.seconds}};
}

RayStats raysFromJson(const nlohmann::ordered_json& j) {
    RayStats r;
    if (!j.is_object()) return r;
    r.cameraRays = j.value("camera", uint64_t(0));
    r.bounceRays = j.value("bounce", uint64_t(0));
    r.shadowRays = j.value("shadow", uint64_t(0));
    r.seconds = j.value("seconds", 0.0);
    return r;
}

/** The sidecar of a new or continued entry; `previous` is the stored one (or empty). */
nlohmann::ordered_json makeSidecar(const ReferenceKey& key, const ReferenceSettings& settings,
                                   const StopCriteria& stop, const ReferenceResult& r,
                                   const std::string& tracerText,
                                   const nlohmann::ordered_json& previous,
                                   const nlohmann::ordered_json& extra) {
    RayStats total = raysFromJson(previous.value("rays", nlohmann::ordered_json()));
    total.cameraRays += r.report.rays.cameraRays;
    total.bounceRays += r.report.rays.bounceRays;
    total.shadowRays += r.report.rays.shadowRays;
    total.seconds += r.report.rays.seconds;
    const int threads = tbb::this_task_arena::max_concurrency();
    const double rate = r.report.rays.seconds > 0.0
                            ? double(r.report.rays.totalRays()) / r.report.rays.seconds
                            : 0.0;
    nlohmann::ordered_json history = previous.value("history", nlohmann::ordered_json::array());
    history.push_back({{"from_samples", r.continuedFromSamples},
                       {"to_samples", r.acc.samples},
                       {"seconds", r.report.seconds},
                       {"cpu_seconds", r.report.cpuSeconds},
                       {"stop_reason", stopReasonName(r.reason)},
                       {"nonfinite_samples", r.report.rays.nonFiniteSamples},
                       {"threads", threads},
                       {"rays_per_second", rate}});

    nlohmann::ordered_json s;
    s["status"] = r.complete ? "complete" : "partial";
    s["key"] = key.hex;
    s["samples"] = r.acc.samples;
    s["seconds"] = previous.value("seconds", 0.0) + r.report.seconds;
    s["cpu_seconds"] = previous.value("cpu_seconds", 0.0) + r.report.cpuSeconds;
    s["rel_error"] = meanRelativeStdError(r.acc);
    s["stop_reason"] = stopReasonName(r.reason);
    s["nonfinite_samples"] = r.acc.nonFiniteSamples;  // dropped (added 0), over all pixels
    s["request"] = stopCriteriaJson(stop);
    s["settings"] = settingsJson(settings);
    s["renderer"] = {{"version", kRendererVersion},     {"tracer", tracerText},
                     {"embree", RTC_VERSION_STRING},    {"compiler", build::kCompiler},
                     {"build_type", build::kBuildType}, {"git_commit", build::kGitCommit}};
    s["threads"] = threads;
    s["rays"] = raysJson(total);
    s["history"] = std::move(history);
    s["key_description"] = key.description;
    for (const auto& item : extra.items())
        if (!s.contains(item.key())) s[item.key()] = item.value();
    return s;
}

}  // namespace

ReferenceResult obtainReference(const Scene& scene, const ReferenceSettings& settings,
                                const StopCriteria& stop, const ReferenceCache* cache,
                                const ObtainOptions& options) {
    if (stop.maxSamples == 0 && stop.targetRelError <= 0.0 && stop.maxSeconds <= 0.0)
        throw Error("reference: no stop criterion (set samples, relative error or seconds)");
    ReferenceResult r;
    const ReferenceKey key = computeReferenceKey(scene, settings);
    r.key = key.hex;
    const int width = scene.settings.width;
    const int height = scene.settings.height;

    // 0. One process per key renders; the others wait here, then find its entry in step 1
    std::optional<FileLock> lock;
    if (cache) {
        lock = FileLock::acquire(cache->lockPath(r.key), options.cancel, [&] {
            std::fprintf(stderr,
                         "[gilab] reference %s is being rendered by another process; waiting "
                         "for it (lock %s)\n",
                         r.key.c_str(), cache->lockPath(r.key).string().c_str());
        });
        if (!lock) {
            r.reason = StopReason::Cancelled;
            return r;
        }
        cache->removeTemporariesOf(r.key);  // only a dead process can have left any
    }

    // 1. A stored entry: reuse it, or continue from it
    std::optional<CachedReference> stored;
    if (cache) {
        try {
            stored = cache->load(r.key);
        } catch (const Error& e) {
            r.warnings.push_back(std::string(e.what()) + "; ignoring the entry, rendering again");
        }
        if (stored && (stored->acc.width != width || stored->acc.height != height)) {
            r.warnings.push_back(stored->dir.string() + ": resolution differs from the key's " +
                                 "scene; ignoring the entry, rendering again");
            stored.reset();
        }
    }
    if (stored) {
        const double relError = meanRelativeStdError(stored->acc);
        StopCriteria noTime = stop;
        noTime.maxSeconds = 0.0;  // a partial entry never meets a time budget
        const std::optional<StopReason> met =
            metCriterion(stored->acc.samples, relError, stored->complete ? stop : noTime);
        if (met) {
            r.cacheHit = true;
            r.complete = true;
            r.reason = *met;
            r.acc = std::move(stored->acc);
            r.sidecar = std::move(stored->sidecar);
            if (!stored->complete) {  // a partial entry whose samples already meet the request
                r.sidecar["status"] = "complete";
                r.sidecar["stop_reason"] = stopReasonName(*met);
                cache->store(r.key, r.acc, r.sidecar);
            }
            return r;
        }
        r.continuedFromSamples = stored->acc.samples;
        r.acc = std::move(stored->acc);
    } else {
        r.acc.reset(width, height);
    }

    // 2. Render until the criteria are met (or cancelled, at a batch boundary)
    PathTracer tracer(scene, settings);
    r.report = renderUntil(tracer, r.acc, stop, options.cancel, options.longReference);
    r.reason = r.report.reason;
    r.complete = r.reason != StopReason::Cancelled;
    r.renderedSamples = r.acc.samples - r.continuedFromSamples;
    r.sidecar = makeSidecar(key, settings, stop, r, tracer.toString(),
                            stored ? stored->sidecar : nlohmann::ordered_json::object(),
                            options.sidecarExtra);

    // 3. Store (also a partial result: it is continued, never trusted, later); a render
    //    cancelled before its first batch changed nothing
    if (cache && r.renderedSamples > 0) cache->store(r.key, r.acc, r.sidecar);
    return r;
}

}  // namespace gilab::ref
