#include "experiments/runner/run_store.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <fstream>
#include <sstream>
#include <unordered_map>
#include <unordered_set>

#include "core/util/error.h"

namespace gilab::exp {
namespace fs = std::filesystem;

namespace {

void syncFile(const fs::path& path) {
    const int fd = ::open(path.c_str(), O_RDONLY);
    if (fd >= 0) {
        ::fsync(fd);
        ::close(fd);
    }
}

std::string csvEscape(const std::string& s) {
    if (s.find_first_of(",\"\n") == std::string::npos) return s;
    std::string out = "\"";
    for (char c : s)
        out += c == '"' ? std::string("\"\"") : std::string(1, c);
    return out + "\"";
}

void appendLine(const fs::path& path, const std::string& line) {
    std::ofstream out(path, std::ios::app);
    out << line << "\n";
    out.flush();
    if (!out) throw Error("cannot append to " + path.string());
    out.close();
    syncFile(path);
}

}  // namespace

std::string sanitizeLabel(const std::string& label) {
    std::string out = label;
    for (char& c : out)
        if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_')) c = '_';
    return out;
}

namespace {

using Json = nlohmann::ordered_json;

/** r at `path`, or null. */
Json jsonAt(const Json& r, std::initializer_list<const char*> path) {
    const Json* node = &r;
    for (const char* key : path) {
        if (!node->is_object() || !node->contains(key)) return nullptr;
        node = &(*node)[key];
    }
    return *node;
}

/** The headline numbers of one metrics::toJson() result, under `prefix`. */
void addMetricColumns(Json& row, const std::string& prefix, const Json& m) {
    if (!m.is_object()) return;
    const Json bars = jsonAt(m, {"error_bars"});
    row[prefix + ".flip"] = jsonAt(m, {"flip", "mean"});
    row[prefix + ".flip_noise"] = jsonAt(bars, {"flip", "spread"});
    row[prefix + ".flip_ldr"] = jsonAt(m, {"flip_ldr", "mean"});
    row[prefix + ".rel_mse"] = jsonAt(m, {"rel_mse"});
    row[prefix + ".rel_mse_sigma"] = jsonAt(bars, {"rel_mse_sigma"});
    row[prefix + ".rel_mse_noise_floor"] = jsonAt(bars, {"rel_mse_noise_floor"});
    row[prefix + ".rel_mse_debiased"] = jsonAt(bars, {"rel_mse_debiased"});
    row[prefix + ".psnr_ldr"] = jsonAt(m, {"psnr_ldr"});
    row[prefix + ".psnr_hdr"] = jsonAt(m, {"psnr_hdr"});
    row[prefix + ".ssim"] = jsonAt(m, {"ssim"});
    row[prefix + ".within_reference_noise"] = jsonAt(m, {"within_reference_noise"});
}

/** NaN / Inf / negative pixels summed over every output layer. */
void addNonFiniteColumns(Json& row, const Json& nonfinite) {
    if (!nonfinite.is_object()) return;
    long long nan = 0, inf = 0, negative = 0;
    for (const auto& [layer, counts] : nonfinite.items()) {
        if (!counts.is_object()) continue;
        nan += counts.value("nan_pixels", 0LL);
        inf += counts.value("inf_pixels", 0LL);
        negative += counts.value("negative_pixels", 0LL);
    }
    row["nan_pixels"] = nan;
    row["inf_pixels"] = inf;
    row["negative_pixels"] = negative;
}

}  // namespace

nlohmann::ordered_json resultRow(const nlohmann::ordered_json& r) {
    auto at = [&](std::initializer_list<const char*> path) { return jsonAt(r, path); };
    Json row = {{"key", at({"key"})},
                {"index", at({"index"})},
                {"experiment", at({"experiment"})},
                {"scene", at({"scene", "label"})},
                {"technique", at({"technique", "id"})},
                {"bounces", at({"technique", "indirect_bounces"})},
                {"status", at({"status"})},
                {"reason", at({"reason"})}};
    // One column per parameter (technique: param.<key>; shared passes: shared.<key>), the
    // swept keys, and the compact "params" text of the technique's parameters.
    std::string params, swept;
    // Named copies: a temporary's items() would dangle in a range-for (before C++23).
    const Json techniqueParams = at({"technique", "params"}), sharedParams = at({"shared_params"}),
               sweptKeys = at({"technique", "swept"}), ladder = at({"metrics", "final_vs_bounces"}),
               regions = at({"metrics", "regions"}), floors = at({"metrics", "bounce_floors"});
    for (const auto& [k, v] : techniqueParams.items()) {
        row["param." + k] = v;
        params += (params.empty() ? "" : " ") + k + "=" +
                  (v.is_string() ? v.get<std::string>() : v.dump());
    }
    for (const auto& [k, v] : sharedParams.items())
        row["shared." + k] = v;
    for (const auto& [k, v] : sweptKeys.items())
        swept += (swept.empty() ? "" : " ") + k;
    row["params"] = params;
    row["swept"] = swept;
    row["validation_errors"] = at({"validation", "errors"});
    row["validation_warnings"] = at({"validation", "warnings"});
    row["setup_ms"] = at({"timing", "setup_ms", "total"});
    row["frame_cpu_ms_median"] = at({"timing", "frame_cpu_ms", "median"});
    row["frame_cpu_ms_iqr"] = at({"timing", "frame_cpu_ms", "iqr"});
    row["frame_gpu_ms_median"] = at({"timing", "frame_gpu_ms", "median"});
    row["frame_gpu_ms_iqr"] = at({"timing", "frame_gpu_ms", "iqr"});
    row["memory_bytes"] = at({"memory", "total_bytes"});
    row["reference_matched"] = at({"reference", "matched"});
    row["reference_samples"] = at({"reference", "samples"});
    row["reference_rel_error"] = at({"reference", "rel_error"});
    // Every basis the report shows (docs/experiments.md "Result tables"): full = all light
    // paths (the headline), matched = the bounces the technique claims, indirect, direct.
    addMetricColumns(row, "full", at({"metrics", "final_vs_full"}));
    addMetricColumns(row, "matched", at({"metrics", "final"}));
    addMetricColumns(row, "indirect", at({"metrics", "indirect"}));
    addMetricColumns(row, "direct", at({"metrics", "direct"}));
    row["energy_ratio"] = at({"metrics", "energy_ratio"});
    for (const auto& [n, m] : ladder.items())
        addMetricColumns(row, "bounces" + n, m);
    // The bounce floors (the path tracer's b-bounce image against the full reference): the same
    // columns as full.*, null with floor<b>.same_as_full when the b-bounce image is the full one.
    for (const auto& [n, m] : floors.items()) {
        const bool same = jsonAt(m, {"same_as_full"}) == Json(true);
        row["floor" + n + ".same_as_full"] = same;
        addMetricColumns(row, "floor" + n, same ? Json::object() : m);
    }
    for (const auto& [name, region] : regions.items()) {
        const std::string prefix = "region." + name;
        row[prefix + ".pixels"] = jsonAt(region, {"pixels"});
        row[prefix + ".energy_ratio"] = jsonAt(region, {"energy_ratio"});
        addMetricColumns(row, prefix + ".matched", jsonAt(region, {"final"}));
        addMetricColumns(row, prefix + ".indirect", jsonAt(region, {"indirect"}));
    }
    // Animated scenes (docs/experiments.md "Animated scenes"): the sequence and dynamic frames.
    if (at({"animation"}).is_object()) {
        row["animation_frames"] = at({"animation", "frames"});
        row["update_kind"] = at({"animation", "update"});
        row["dynamic_frame_gpu_ms_median"] = at({"timing", "dynamic_frame_gpu_ms", "median"});
        row["dynamic_frame_gpu_ms_iqr"] = at({"timing", "dynamic_frame_gpu_ms", "iqr"});
        row["dynamic_frame_cpu_ms_median"] = at({"timing", "dynamic_frame_cpu_ms", "median"});
        row["update_cpu_ms_median"] = at({"timing", "update_cpu_ms", "median"});
        row["sequence.full.flip_mean"] = at({"metrics", "sequence", "full_flip_mean"});
        row["sequence.full.rel_mse_mean"] = at({"metrics", "sequence", "full_rel_mse_mean"});
        row["sequence.matched.flip_mean"] = at({"metrics", "sequence", "matched_flip_mean"});
        for (const char* basis : {"temporal", "temporal_matched"}) {
            const std::string prefix = std::string("sequence.") + basis;
            row[prefix + ".instability"] =
                at({"metrics", "sequence", basis, "temporal_instability"});
            row[prefix + ".p95"] = at({"metrics", "sequence", basis, "p95"});
            row[prefix + ".noise_floor"] = at({"metrics", "sequence", basis, "noise_floor"});
            row[prefix + ".debiased"] = at({"metrics", "sequence", basis, "debiased"});
        }
    }
    const Json stats = at({"stats"});  // technique numbers (TechniqueContext::stat)
    if (stats.is_object())
        for (const auto& [name, value] : stats.items())
            row["stat." + name] = value;
    addNonFiniteColumns(row, at({"nonfinite"}));
    row["output_exr"] = at({"outputs", "exr"}).is_string()
                            ? Json("runs/" + at({"key"}).get<std::string>() + "/" +
                                   at({"outputs", "exr"}).get<std::string>())
                            : Json(nullptr);
    row["device"] = at({"device", "name"});
    row["device_type"] = at({"device", "type"});
    row["driver"] = at({"device", "driver_info"});
    row["vulkan_api"] = at({"device", "vulkan_api"});
    row["config_hash"] = at({"config_hash"});
    row["git_commit"] = at({"provenance", "git_commit"});
    row["date"] = at({"provenance", "date"});
    return row;
}

bool isFinalStatus(const std::string& status) {
    return status == "ok" || status == "nonfinite" || status == "unsupported";
}

bool isStoredStatus(const std::string& status) {
    return isFinalStatus(status) || status == "invalid";
}

std::string runStatus(const RunOutcome& outcome) {
    if (outcome.validationMessages > 0) return "invalid";
    if (!outcome.supported) return "unsupported";
    return outcome.nonFinitePixels > 0 ? "nonfinite" : "ok";
}

void flattenJson(const nlohmann::ordered_json& value, const std::string& prefix,
                 std::vector<std::pair<std::string, std::string>>& out) {
    if (value.is_object()) {
        for (const auto& [k, v] : value.items())
            flattenJson(v, prefix.empty() ? k : prefix + "." + k, out);
    } else if (value.is_string()) {
        out.emplace_back(prefix, value.get<std::string>());
    } else if (value.is_null()) {
        out.emplace_back(prefix, "");
    } else {
        out.emplace_back(prefix, value.dump());
    }
}

RunStore::RunStore(fs::path experimentDir, bool create) : m_dir(std::move(experimentDir)) {
    std::error_code ec;
    if (fs::exists(m_dir, ec) && !fs::is_directory(m_dir, ec))
        throw Error("cannot write the experiment's results to " + m_dir.string() + ": it is a " +
                    "file, not a folder");
    if (create) fs::create_directories(m_dir / "runs");
}

fs::path RunStore::runDir(const std::string& key) const {
    return m_dir / "runs" / key;
}

std::string RunStore::storedStatus(const std::string& key) const {
    const fs::path result = runDir(key) / "result.json";
    if (!fs::exists(result)) return "";
    try {
        std::ifstream in(result);
        const nlohmann::json j = nlohmann::json::parse(in);
        return j.value("status", "");
    } catch (const std::exception&) {
        return "";  // unreadable: redo the run
    }
}

bool RunStore::isFinished(const std::string& key) const {
    return isFinalStatus(storedStatus(key));
}

std::optional<FileLock> RunStore::tryClaim(const std::string& key) const {
    return FileLock::tryAcquire(m_dir / "runs" / ".locks" / (key + ".lock"));
}

std::optional<FileLock> RunStore::claim(const std::string& key,
                                        const std::atomic<bool>* cancel) const {
    return FileLock::acquire(m_dir / "runs" / ".locks" / (key + ".lock"), cancel);
}

fs::path RunStore::beginRun(const std::string& key) const {
    for (const auto& entry : fs::directory_iterator(m_dir / "runs")) {
        const std::string name = entry.path().filename().string();
        if (name.rfind(".tmp-" + key + "-", 0) == 0 || name.rfind(".old-" + key + "-", 0) == 0)
            fs::remove_all(entry.path());
    }
    const fs::path tmp = m_dir / "runs" / (".tmp-" + key + "-" + processTag());
    fs::create_directories(tmp);
    return tmp;
}

void RunStore::commitRun(const fs::path& tmpDir, const std::string& key) const {
    const fs::path target = runDir(key);
    if (fs::exists(target)) {
        const fs::path aside = m_dir / "runs" / (".old-" + key + "-" + processTag());
        fs::rename(target, aside);
        fs::rename(tmpDir, target);
        fs::remove_all(aside);
    } else {
        fs::rename(tmpDir, target);
    }
}

void RunStore::appendRow(const nlohmann::ordered_json& row) const {
    const std::optional<FileLock> lock = FileLock::acquire(m_dir / ".locks" / "results.lock");
    appendLine(m_dir / "results.jsonl", row.dump());
    writeCsv();
}

size_t RunStore::addMissingRows() const {
    const std::optional<FileLock> lock = FileLock::acquire(m_dir / ".locks" / "results.lock");
    std::unordered_set<std::string> listed;
    {
        std::ifstream in(m_dir / "results.jsonl");
        std::string line;
        while (std::getline(in, line)) {
            try {
                listed.insert(nlohmann::json::parse(line).value("key", std::string()));
            } catch (const std::exception&) {
            }
        }
    }
    size_t added = 0;
    for (const nlohmann::json& result : loadFinished()) {
        if (listed.count(result.value("key", std::string()))) continue;
        appendLine(m_dir / "results.jsonl", resultRow(nlohmann::ordered_json(result)).dump());
        ++added;
    }
    if (added) writeCsv();
    return added;
}

void RunStore::writeCsv() const {
    // results.csv is derived from results.jsonl (the append-only record): its columns are the
    // union over every row in first-seen order, so runs of different techniques (different
    // parameters) each keep all their columns. Rewritten atomically after every row.
    std::vector<std::vector<std::pair<std::string, std::string>>> rows;
    std::vector<std::string> header;
    std::unordered_set<std::string> seen;
    std::ifstream in(m_dir / "results.jsonl");
    std::string line;
    while (std::getline(in, line)) {
        if (line.empty()) continue;
        nlohmann::ordered_json row;
        try {
            row = nlohmann::ordered_json::parse(line);
        } catch (const std::exception&) {
            continue;  // a torn last line of a killed run: the run is redone anyway
        }
        rows.emplace_back();
        flattenJson(row, "", rows.back());
        for (const auto& [k, v] : rows.back())
            if (seen.insert(k).second) header.push_back(k);
    }
    std::string out;
    for (size_t i = 0; i < header.size(); ++i) {
        if (i) out += ',';
        out += csvEscape(header[i]);
    }
    out += "\n";
    for (const auto& cells : rows) {
        std::unordered_map<std::string, const std::string*> byKey;
        for (const auto& [k, v] : cells)
            byKey[k] = &v;
        for (size_t i = 0; i < header.size(); ++i) {
            if (i) out += ',';
            auto it = byKey.find(header[i]);
            if (it != byKey.end()) out += csvEscape(*it->second);
        }
        out += "\n";
    }
    writeFileAtomic(m_dir / "results.csv", out);
}

std::vector<nlohmann::json> RunStore::loadFinished() const {
    std::vector<nlohmann::json> out;
    for (const auto& entry : fs::directory_iterator(m_dir / "runs")) {
        const std::string name = entry.path().filename().string();
        if (name.empty() || name[0] == '.') continue;
        const fs::path result = entry.path() / "result.json";
        if (!fs::exists(result)) continue;
        try {
            std::ifstream in(result);
            nlohmann::json j = nlohmann::json::parse(in);
            if (isStoredStatus(j.value("status", ""))) out.push_back(std::move(j));
        } catch (const std::exception&) {
        }
    }
    std::sort(out.begin(), out.end(), [](const nlohmann::json& a, const nlohmann::json& b) {
        return std::make_pair(a.value("index", 0), a.value("key", std::string())) <
               std::make_pair(b.value("index", 0), b.value("key", std::string()));
    });
    return out;
}

}  // namespace gilab::exp
