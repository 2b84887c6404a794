// One technique x case of the audit: a one-run experiment config, `gilab run` in a child
// process, and the numbers the grading needs from its result.json and output.exr.
#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>

#include "core/image/color.h"
#include "core/image/image_io.h"
#include "core/technique/registry.h"
#include "core/util/atomic_file.h"
#include "core/util/error.h"
#include "core/util/json_reader.h"
#include "experiments/audit/audit_internal.h"
#include "experiments/audit/child_process.h"
#include "experiments/runner/run_metadata.h"

namespace gilab::audit {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

namespace {

/** A --set style value as JSON: a number or boolean when it reads as one, else a string. */
Json valueJson(const std::string& text) {
    if (text == "true") return true;
    if (text == "false") return false;
    double v = 0.0;
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
    if (ec == std::errc() && end == text.data() + text.size()) {
        if (text.find_first_of(".eE") == std::string::npos) return int64_t(std::llround(v));
        return v;
    }
    return text;
}

Json referenceJson(const AuditCase& c, const Profile& p) {
    return {{"spp", p.spp},
            {"max_bounces", c.maxBounces.value_or(p.maxBounces)},
            {"seed", 1},
            {"pixel_filter", "center"},
            {"roulette_start_bounce", c.rouletteStart},
            {"frames", 1}};
}

/** The cell's experiment config: one scene, one technique, no sweep. */
Json cellConfig(const CellRequest& r, const std::string& name) {
    const ParamSet defaults = TechniqueRegistry::instance().defaultParams(r.technique);
    Json params = Json::object(), shared = Json::object();
    auto put = [&](const std::string& key, const std::string& value) {
        if (key.rfind("shared.", 0) == 0)
            shared[key.substr(7)] = valueJson(value);
        else
            params[key] = valueJson(value);
    };
    if (auto it = r.catalog.techniqueParams.find(r.technique);
        it != r.catalog.techniqueParams.end())
        for (const auto& [k, v] : it->second)
            if (defaults.has(k)) put(k, v);
    if (defaults.has("voxel_resolution"))
        put("voxel_resolution", std::to_string(r.profile.voxelResolution));
    if (auto it = r.c.params.find(r.technique); it != r.c.params.end())
        for (const auto& [k, v] : it->second)
            put(k, v);
    Json technique = {{"technique", r.technique}, {"params", params}};
    if (!shared.empty()) technique["shared"] = shared;
    return {{"name", name},
            {"description", "gilab audit: " + r.c.name + " (" + r.c.what + ") x " + r.technique},
            {"resolution",
             {r.c.resolution ? r.c.resolution->x : r.profile.width,
              r.c.resolution ? r.c.resolution->y : r.profile.height}},
            {"scenes", {r.c.scene}},
            {"reference", referenceJson(r.c, r.profile)},
            {"timing", {{"warmup", r.profile.warmupFrames}, {"frames", r.profile.frames}}},
            {"techniques", {technique}}};
}

size_t count(const Json& j, const char* key) {
    return j.contains(key) && j[key].is_number() ? j[key].get<size_t>() : 0;
}

/** NaN / Inf / negative pixels of the radiance layers of a {"layer": {...}} block. */
void addNonFinite(const Json& block, CellResult& cell) {
    if (!block.is_object()) return;
    for (const auto& [layer, counts] : block.items()) {
        if (!cli::isRadianceLayer(layer)) continue;
        cell.nanPixels += count(counts, "nan_pixels");
        cell.infPixels += count(counts, "inf_pixels");
        cell.negativePixels += count(counts, "negative_pixels");
    }
}

std::optional<double> numberAt(const Json& j, std::initializer_list<const char*> path) {
    const Json* node = &j;
    for (const char* key : path) {
        if (!node->is_object() || !node->contains(key)) return std::nullopt;
        node = &(*node)[key];
    }
    if (!node->is_number()) return std::nullopt;
    return node->get<double>();
}

/** The energy ratio farthest from 1 (in log terms) over the static frame and the sequence. */
std::optional<double> worstEnergy(const Json& result) {
    std::optional<double> worst = numberAt(result, {"metrics", "energy_ratio"});
    auto farther = [](double a, double b) {
        return std::abs(std::log(std::max(a, 1e-12))) > std::abs(std::log(std::max(b, 1e-12)));
    };
    if (result.contains("metrics") && result["metrics"].contains("sequence"))
        for (const Json& f : result["metrics"]["sequence"]["frames"]) {
            const std::optional<double> e = numberAt(f, {"energy_ratio"});
            if (e && (!worst || farther(*e, *worst))) worst = e;
        }
    return worst;
}

/**
 * Animated cases: light in a frame whose reference is black (below 1e-3 of the brightest
 * frame's mean, e.g. the light inside a wall), over the brightest reference frame's mean.
 */
std::optional<double> darkFrameLeak(const Json& result) {
    if (!result.contains("metrics") || !result["metrics"].contains("sequence")) return std::nullopt;
    const Json& frames = result["metrics"]["sequence"]["frames"];
    double brightest = 0.0;
    for (const Json& f : frames)
        brightest = std::max(brightest, numberAt(f, {"reference_mean_luminance"}).value_or(0.0));
    std::optional<double> leak;
    for (const Json& f : frames) {
        const std::optional<double> ref = numberAt(f, {"reference_mean_luminance"});
        const std::optional<double> test = numberAt(f, {"final_mean_luminance"});
        if (!ref || !test || !(brightest > 0.0) || *ref > 1e-3 * brightest) continue;
        leak = std::max(leak.value_or(0.0), *test / brightest);
    }
    return leak;
}

void readResult(const fs::path& runDir, CellResult& cell) {
    const Json result = Json::parse(std::ifstream(runDir / "result.json"));
    cell.runDir = runDir.string();
    const std::string status = result.value("status", "");
    if (status == "unsupported") {
        cell.outcome = "unsupported";
        cell.message = result.value("reason", "");
        return;
    }
    addNonFinite(result["nonfinite"], cell);
    if (result.contains("metrics") && result["metrics"].contains("sequence"))
        for (const Json& f : result["metrics"]["sequence"]["frames"])
            if (f.contains("nonfinite")) addNonFinite(f["nonfinite"], cell);
    const Json& v = result["validation"];
    cell.validationMessages = uint32_t(count(v, "errors") + count(v, "warnings"));
    // A technique that claims no indirect bounce (direct) has no indirect energy to compare.
    if (numberAt(result, {"technique", "indirect_bounces"}).value_or(1.0) != 0.0)
        cell.energyRatio = worstEnergy(result);
    cell.clampedPercent = numberAt(result, {"stats", "clamped_energy_percent"});
    cell.leak = darkFrameLeak(result);
    cell.setupMs = numberAt(result, {"timing", "setup_ms", "total"}).value_or(0.0);
    cell.frameMs =
        numberAt(result, {"timing", "frame_gpu_ms", "median"})
            .value_or(numberAt(result, {"timing", "frame_cpu_ms", "median"}).value_or(0.0));
    cell.peakMemoryMiB =
        numberAt(result, {"memory", "peak_bytes"}).value_or(0.0) / (1024.0 * 1024.0);
    // Peak and mean of the final image against the matched reference's
    const std::vector<ImageLayer> layers = readExrLayers((runDir / "output.exr").string());
    const Image* final = findLayer(layers, "final");
    if (final) cell.meanLuminance = meanLuminance(*final);
    const std::string refExr = result["reference"].value("final_exr", "");
    if (final && !refExr.empty() && fs::exists(runDir / refExr)) {
        const Image ref = readImageRgb((runDir / refExr).string());
        const double refPeak = maxLuminance(ref);
        if (refPeak > 0.0) cell.peakRatio = maxLuminance(*final) / refPeak;
    }
}

}  // namespace

CellResult runCell(const CellRequest& r) {
    CellResult cell;
    cell.technique = r.technique;
    cell.caseName = r.c.name;
    const std::string name = r.c.name + "-" + r.technique;
    const fs::path config = r.paths.configs() / (name + ".json");
    fs::create_directories(config.parent_path());
    writeFileAtomic(config, cellConfig(r, name).dump(2) + "\n");
    const fs::path log = r.paths.logs() / (name + ".log");
    fs::remove(log);
    std::vector<std::string> args{
        (r.options.executable.empty() ? selfExecutable() : r.options.executable),
        "run",
        config.string(),
        "--out",
        r.paths.cells().string(),
        "--reference-cache",
        r.paths.cache.string(),
        "--quiet"};
    if (r.options.validation) args.push_back("--validation");
    if (!r.options.device.empty()) args.insert(args.end(), {"--device", r.options.device});
    const ChildExit e = runChild(args, log, r.profile.cellTimeoutS, r.options.cancel);
    cell.exitCode = e.code;
    if (e.cancelled || (e.exited && e.code == 130)) {
        cell.outcome = "cancelled";
        return cell;
    }
    if (e.timedOut) {
        cell.outcome = "timeout";
        cell.message = "no result after " + std::to_string(int(r.profile.cellTimeoutS)) +
                       " s (log: " + log.string() + ")";
        return cell;
    }
    if (!e.exited) {
        cell.outcome = "crash";
        cell.message =
            std::string("killed by signal ") + strsignal(e.signal) + " (log: " + log.string() + ")";
        return cell;
    }
    if (e.code == 1 || e.code == 2 || e.code == 127) {
        cell.outcome = r.c.parameterCase && e.code == 1 ? "refused" : "error";
        cell.message = lastErrorLine(log);
        return cell;
    }
    // 0 ok, 3 unsupported, 4 non-finite, 5 validation: the run is committed
    const fs::path runs = r.paths.cells() / name / "runs";
    fs::path runDir;
    if (fs::is_directory(runs))
        for (const auto& entry : fs::directory_iterator(runs))
            if (fs::exists(entry.path() / "result.json")) runDir = entry.path();
    if (runDir.empty()) {
        cell.outcome = "error";
        cell.message = "exit code " + std::to_string(e.code) +
                       " but no committed run (log: " + log.string() + ")";
        return cell;
    }
    cell.outcome = "ok";
    try {
        readResult(runDir, cell);
    } catch (const std::exception& ex) {
        cell.outcome = "error";
        cell.message = runDir.string() + ": cannot read the run's result: " + ex.what();
    }
    return cell;
}

}  // namespace gilab::audit
