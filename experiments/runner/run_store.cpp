#include "experiments/runner/run_store.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <fstream>
#include <sstream>

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

nlohmann::ordered_json resultRow(const nlohmann::ordered_json& r) {
    auto at = [&](std::initializer_list<const char*> path) -> nlohmann::ordered_json {
        const nlohmann::ordered_json* node = &r;
        for (const char* key : path) {
            if (!node->is_object() || !node->contains(key)) return nullptr;
            node = &(*node)[key];
        }
        return *node;
    };
    std::string params;
    if (r.contains("technique") && r["technique"].contains("params"))
        for (const auto& [k, v] : r["technique"]["params"].items())
            params += (params.empty() ? "" : " ") + k + "=" +
                      (v.is_string() ? v.get<std::string>() : v.dump());
    return {{"key", at({"key"})},
            {"index", at({"index"})},
            {"experiment", at({"experiment"})},
            {"scene", at({"scene", "label"})},
            {"technique", at({"technique", "id"})},
            {"bounces", at({"technique", "indirect_bounces"})},
            {"params", params},
            {"status", at({"status"})},
            {"reason", at({"reason"})},
            {"validation_errors", at({"validation", "errors"})},
            {"validation_warnings", at({"validation", "warnings"})},
            {"setup_ms", at({"timing", "setup_ms", "total"})},
            {"frame_cpu_ms_median", at({"timing", "frame_cpu_ms", "median"})},
            {"frame_cpu_ms_iqr", at({"timing", "frame_cpu_ms", "iqr"})},
            {"frame_gpu_ms_median", at({"timing", "frame_gpu_ms", "median"})},
            {"memory_bytes", at({"memory", "total_bytes"})},
            {"reference_matched", at({"reference", "matched"})},
            {"reference_samples", at({"reference", "samples"})},
            {"psnr_ldr", at({"metrics", "final", "psnr_ldr"})},
            {"rel_mse", at({"metrics", "final", "rel_mse"})},
            {"ssim", at({"metrics", "final", "ssim"})},
            {"flip_mean", at({"metrics", "final", "flip", "mean"})},
            {"within_reference_noise", at({"metrics", "final", "within_reference_noise"})},
            {"flip_mean_vs_full", at({"metrics", "final_vs_full", "flip", "mean"})},
            {"energy_ratio", at({"metrics", "energy_ratio"})},
            {"nan_pixels_final", at({"nonfinite", "final", "nan_pixels"})},
            {"inf_pixels_final", at({"nonfinite", "final", "inf_pixels"})},
            {"device", at({"device", "name"})},
            {"driver", at({"device", "driver_info"})},
            {"vulkan_api", at({"device", "vulkan_api"})},
            {"config_hash", at({"config_hash"})},
            {"git_commit", at({"provenance", "git_commit"})},
            {"date", at({"provenance", "date"})}};
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

void flattenJson(const nlohmann::json& value, const std::string& prefix,
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

RunStore::RunStore(fs::path experimentDir) : m_dir(std::move(experimentDir)) {
    fs::create_directories(m_dir / "runs");
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

fs::path RunStore::beginRun(const std::string& key) const {
    for (const auto& entry : fs::directory_iterator(m_dir / "runs")) {
        const std::string name = entry.path().filename().string();
        if (name.rfind(".tmp-" + key, 0) == 0) fs::remove_all(entry.path());
    }
    const fs::path tmp = m_dir / "runs" / (".tmp-" + key + "-" + std::to_string(::getpid()));
    fs::create_directories(tmp);
    return tmp;
}

void RunStore::commitRun(const fs::path& tmpDir, const std::string& key) const {
    const fs::path target = runDir(key);
    if (fs::exists(target)) {
        const fs::path aside = m_dir / "runs" / (".old-" + key + "-" + std::to_string(::getpid()));
        fs::rename(target, aside);
        fs::rename(tmpDir, target);
        fs::remove_all(aside);
    } else {
        fs::rename(tmpDir, target);
    }
}

void RunStore::appendRow(const nlohmann::ordered_json& row) const {
    appendLine(m_dir / "results.jsonl", row.dump());

    std::vector<std::pair<std::string, std::string>> cells;
    flattenJson(row, "", cells);
    const fs::path csv = m_dir / "results.csv";
    // The header is written once, from the first row; later rows follow its columns (a column
    // the first row lacked is dropped from the CSV but kept in results.jsonl).
    std::vector<std::string> header;
    if (fs::exists(csv)) {
        std::ifstream in(csv);
        std::string line;
        std::getline(in, line);
        std::stringstream ss(line);
        std::string cell;
        while (std::getline(ss, cell, ','))
            header.push_back(cell);
    } else {
        std::string line;
        for (const auto& [k, v] : cells) {
            header.push_back(k);
            if (!line.empty()) line += ',';
            line += csvEscape(k);
        }
        appendLine(csv, line);
    }
    std::string line;
    for (size_t i = 0; i < header.size(); ++i) {
        auto it = std::find_if(cells.begin(), cells.end(),
                               [&](const auto& c) { return c.first == header[i]; });
        if (i) line += ',';
        if (it != cells.end()) line += csvEscape(it->second);
    }
    appendLine(csv, line);
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
