#include "experiments/runner/experiment_config.h"

#include <unistd.h>

#include <cstdio>

#include <algorithm>
#include <bit>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <set>

#include "core/passes/shared_passes.h"
#include "core/technique/frame_harness.h"
#include "core/technique/registry.h"
#include "core/util/error.h"
#include "core/util/json_reader.h"
#include "experiments/runner/pt_baseline.h"

namespace gilab::exp {
namespace {

namespace fs = std::filesystem;

SceneEntry parseScene(const JsonNode& node, const std::string& baseDir, int defaultW,
                      int defaultH) {
    SceneEntry entry;
    std::string spec;
    entry.width = defaultW;
    entry.height = defaultH;
    if (node.raw().is_string()) {
        spec = node.string();
    } else {
        node.expectKeys({"scene", "resolution", "label"});
        spec = node["scene"].string();
        if (node.has("resolution")) {
            const JsonNode r = node["resolution"];
            if (r.arraySize() != 2) r.fail("expected [width, height]");
            entry.width = r.item(0).integerIn(1, 16384);
            entry.height = r.item(1).integerIn(1, 16384);
        }
        if (node.has("label")) entry.label = node["label"].string();
    }
    if (spec.empty()) node.fail("empty scene");
    const size_t hash = spec.find('#');
    std::string file = spec.substr(0, hash);
    if (hash != std::string::npos) entry.variant = spec.substr(hash + 1);
    if (file == "builtin") {
        if (!entry.variant.empty()) node.fail("the built-in scene has no variants");
        entry.path.clear();
    } else {
        fs::path p(file);
        if (p.is_relative()) p = fs::path(baseDir) / p;
        if (!fs::exists(p)) node.fail("scene file not found: " + p.lexically_normal().string());
        entry.path = p.lexically_normal().string();
    }
    if (entry.label.empty()) {
        entry.label = entry.path.empty() ? "builtin" : fs::path(entry.path).stem().string();
        if (!entry.variant.empty()) entry.label += "#" + entry.variant;
    }
    return entry;
}

ReferenceRequest parseReference(const JsonNode& node) {
    ReferenceRequest r;
    node.expectKeys({"spp", "rel_error", "time_s", "max_bounces", "roulette_start_bounce",
                     "roulette_threshold", "seed", "estimator", "batch_spp", "pixel_filter",
                     "sampler", "sobol_replicate", "frames"});
    if (node.has("frames")) {
        const JsonNode f = node["frames"];
        if (f.raw().is_string()) {
            if (f.string() != "all") f.fail("expected \"all\" or an integer k (every k-th frame)");
        } else {
            r.frameStep = f.integerIn(1, 10000);
        }
    }
    if (node.has("spp")) r.stop.maxSamples = uint64_t(node["spp"].integerIn(1, 1 << 24));
    if (node.has("rel_error")) r.stop.targetRelError = node["rel_error"].numberIn(0.0, 10.0);
    if (node.has("time_s")) r.stop.maxSeconds = node["time_s"].numberIn(0.0, 1e7);
    if (r.stop.maxSamples == 0 && r.stop.targetRelError == 0.0 && r.stop.maxSeconds == 0.0)
        node.fail("needs at least one stop criterion: spp, rel_error or time_s");
    if (node.has("max_bounces")) r.settings.maxBounces = node["max_bounces"].integerIn(0, 1024);
    if (node.has("roulette_start_bounce"))
        r.settings.rouletteStartBounce = node["roulette_start_bounce"].integerIn(-1, 1024);
    if (node.has("roulette_threshold"))
        r.settings.rouletteThreshold = float(node["roulette_threshold"].numberIn(1e-6, 1.0));
    if (node.has("seed")) r.settings.seed = uint64_t(node["seed"].integerIn(0, 1 << 30));
    if (node.has("sobol_replicate")) {
        const int64_t n = node["sobol_replicate"].integerIn(1, 1 << 30);
        if (!std::has_single_bit(uint64_t(n)))
            node["sobol_replicate"].fail("expected a power of two (got " + std::to_string(n) + ")");
        r.settings.sobolReplicate = uint32_t(n);
    }
    if (node.has("batch_spp"))
        r.settings.batchSamples = uint32_t(node["batch_spp"].integerIn(1, 4096));
    if (node.has("pixel_filter")) {
        const std::string f = node["pixel_filter"].string();
        if (f == "box")
            r.settings.pixelFilter = ref::PixelFilter::Box;
        else if (f == "center")
            r.settings.pixelFilter = ref::PixelFilter::Center;
        else
            node["pixel_filter"].fail("expected box or center (got \"" + f + "\")");
    }
    if (node.has("sampler")) {
        const std::string k = node["sampler"].string();
        if (k == "independent")
            r.settings.sampler = ref::SamplerKind::Independent;
        else if (k == "sobol")
            r.settings.sampler = ref::SamplerKind::Sobol;
        else
            node["sampler"].fail("expected independent or sobol (got \"" + k + "\")");
    }
    if (node.has("estimator")) {
        const std::string e = node["estimator"].string();
        if (e == "mis")
            r.settings.estimator = ref::Estimator::Mis;
        else if (e == "nee")
            r.settings.estimator = ref::Estimator::NeeOnly;
        else if (e == "bsdf")
            r.settings.estimator = ref::Estimator::BsdfOnly;
        else
            node["estimator"].fail("expected mis, nee or bsdf (got \"" + e + "\")");
    }
    return r;
}

MetricOptionsSpec parseMetrics(const JsonNode& node) {
    MetricOptionsSpec m;
    node.expectKeys({"ppd", "exposure_ev", "regions", "same_vpl_reference"});
    if (node.has("same_vpl_reference")) m.sameVplReference = node["same_vpl_reference"].boolean();
    if (node.has("ppd")) m.ppd = node["ppd"].numberIn(1.0, 1000.0);
    if (node.has("exposure_ev")) m.exposureEv = float(node["exposure_ev"].numberIn(-40.0, 40.0));
    if (node.has("regions")) {
        const JsonNode regions = node["regions"];
        std::set<std::string> names;
        for (size_t i = 0; i < regions.arraySize(); ++i) {
            const JsonNode r = regions.item(i);
            r.expectKeys({"name", "rect", "indirect_fraction_above"});
            RegionSpec spec;
            spec.name = r["name"].string();
            if (!names.insert(spec.name).second) r["name"].fail("duplicate region name");
            if (r.has("rect") == r.has("indirect_fraction_above"))
                r.fail("a region needs exactly one of rect or indirect_fraction_above");
            if (r.has("rect")) {
                const JsonNode rect = r["rect"];
                if (rect.arraySize() != 4) rect.fail("expected [x0, y0, x1, y1] in 0..1");
                std::array<double, 4> v{};
                for (size_t k = 0; k < 4; ++k)
                    v[k] = rect.item(k).numberIn(0.0, 1.0);
                if (v[2] <= v[0] || v[3] <= v[1])
                    rect.fail("empty rectangle (need x1 > x0, y1 > y0)");
                spec.rect = v;
            } else {
                spec.indirectFractionAbove = r["indirect_fraction_above"].numberIn(0.0, 1.0);
            }
            m.regions.push_back(spec);
        }
    }
    return m;
}

std::map<std::string, nlohmann::json> parseAssignments(const JsonNode& node, ParamSet params) {
    std::map<std::string, nlohmann::json> out;
    if (!node.raw().is_object()) node.fail("expected an object of parameter values");
    for (const auto& [key, value] : node.raw().items()) {
        try {
            params.setJson(key, value);  // validates name, type and range now
        } catch (const Error& e) {
            node.fail(e.what());
        }
        out[key] = value;
    }
    return out;
}

/** The parameter set a swept key belongs to: "shared.<key>" sweeps a shared-pass parameter. */
struct AxisTarget {
    ParamSet* params;
    std::string key;
};

AxisTarget axisTarget(const std::string& key, ParamSet& technique, ParamSet& shared) {
    if (key.rfind("shared.", 0) == 0) return {&shared, key.substr(7)};
    return {&technique, key};
}

std::vector<std::pair<std::string, std::vector<nlohmann::json>>> parseAxes(const JsonNode& node,
                                                                           ParamSet technique,
                                                                           ParamSet shared) {
    std::vector<std::pair<std::string, std::vector<nlohmann::json>>> axes;
    if (!node.raw().is_object() || node.raw().empty())
        node.fail("expected a non-empty object {parameter: values}");
    for (const auto& [key, value] : node.raw().items()) {
        const JsonNode axis = node[key.c_str()];
        const AxisTarget target = axisTarget(key, technique, shared);
        if (!target.params->has(target.key)) {
            ParamSet probe = *target.params;
            try {
                probe.set(target.key, "0");  // throws the unknown-key message with the valid keys
            } catch (const Error& e) {
                axis.fail(e.what());
            }
        }
        const bool integer = target.params->spec(target.key).type == ParamType::Int;
        std::vector<nlohmann::json> values;
        if (value.is_array()) {
            values.assign(value.begin(), value.end());
        } else if (value.is_object()) {
            values = expandRange(value, integer, axis.context() + ": \"" + axis.path() + "\"");
        } else {
            axis.fail(
                "expected a list of values or a range {\"linear\"|\"log\": [from, to, count]}");
        }
        if (values.empty()) axis.fail("no values to sweep");
        ParamSet probe = *target.params;
        for (const nlohmann::json& v : values) {
            try {
                probe.setJson(target.key, v);
            } catch (const Error& e) {
                axis.fail(e.what());
            }
        }
        axes.emplace_back(key, std::move(values));
    }
    return axes;
}

TechniqueEntry parseTechnique(const JsonNode& node, const std::set<std::string>& sceneLabels) {
    node.expectKeys(
        {"technique", "params", "sweep", "shared", "scenes", "repeats", "frames", "warmup"});
    TechniqueEntry t;
    t.id = node["technique"].string();
    if (node.has("repeats")) t.repeats = node["repeats"].integerIn(1, 1000);
    if (node.has("frames")) t.timedFrames = node["frames"].integerIn(1, 100000);
    if (node.has("warmup")) t.warmupFrames = node["warmup"].integerIn(0, 1000);
    if (node.has("scenes")) {
        // Only these scenes (labels as in "scenes"), e.g. a sweep that matters on one scene.
        const JsonNode list = node["scenes"];
        if (list.arraySize() == 0) list.fail("expected a non-empty list of scene labels");
        for (size_t i = 0; i < list.arraySize(); ++i) {
            const std::string label = list.item(i).string();
            if (!sceneLabels.count(label)) {
                std::string known;
                for (const std::string& l : sceneLabels)
                    known += (known.empty() ? "" : ", ") + l;
                list.item(i).fail("no scene labelled \"" + label + "\" (scenes: " + known + ")");
            }
            t.scenes.push_back(label);
        }
    }
    ParamSet params;
    try {
        params = defaultRunParams(t.id);
    } catch (const Error& e) {
        node["technique"].fail(e.what());
    }
    if (node.has("params")) t.fixed = parseAssignments(node["params"], params);
    for (const auto& [k, v] : t.fixed)
        params.setJson(k, v);
    if (node.has("shared")) t.shared = parseAssignments(node["shared"], defaultSharedParams());
    if (node.has("sweep")) {
        const JsonNode sweep = node["sweep"];
        sweep.expectKeys({"grid", "zip"});
        const ParamSet shared = defaultSharedParams();
        if (sweep.has("grid")) t.grid = parseAxes(sweep["grid"], params, shared);
        if (sweep.has("zip")) {
            t.zip = parseAxes(sweep["zip"], params, shared);
            for (const auto& [key, values] : t.zip)
                if (values.size() != t.zip.front().second.size())
                    sweep["zip"].fail("zipped lists must have equal lengths (\"" + key + "\" has " +
                                      std::to_string(values.size()) + ", \"" + t.zip.front().first +
                                      "\" has " + std::to_string(t.zip.front().second.size()) +
                                      ")");
        }
        std::set<std::string> seen;
        for (const auto& axes : {t.grid, t.zip})
            for (const auto& [key, values] : axes) {
                if (!seen.insert(key).second || t.fixed.count(key) ||
                    (key.rfind("shared.", 0) == 0 && t.shared.count(key.substr(7))))
                    sweep.fail("parameter \"" + key + "\" is set more than once");
            }
    }
    return t;
}

}  // namespace

std::vector<nlohmann::json> expandRange(const nlohmann::json& range, bool integer,
                                        const std::string& where) {
    if (range.size() != 1 || !(range.contains("linear") || range.contains("log")))
        throw Error(where + ": a range is {\"linear\": [from, to, count]} or {\"log\": [...]}");
    const bool log = range.contains("log");
    const nlohmann::json& a = log ? range["log"] : range["linear"];
    if (!a.is_array() || a.size() != 3 || !a[0].is_number() || !a[1].is_number() ||
        !a[2].is_number_integer())
        throw Error(where + ": range needs [from, to, count] with an integer count");
    const double from = a[0].get<double>(), to = a[1].get<double>();
    const int count = a[2].get<int>();
    if (!std::isfinite(from) || !std::isfinite(to) || count < 1 || count > 1000)
        throw Error(where + ": range from/to must be finite and count in [1, 1000]");
    if (log && (from <= 0.0 || to <= 0.0))
        throw Error(where + ": a log range needs positive from and to");
    std::vector<nlohmann::json> values;
    for (int i = 0; i < count; ++i) {
        const double t = count == 1 ? 0.0 : double(i) / double(count - 1);
        const double v = log ? from * std::pow(to / from, t) : from + (to - from) * t;
        if (integer) {
            const long long r = std::llround(v);
            if (values.empty() || values.back().get<long long>() != r) values.push_back(r);
        } else {
            values.push_back(v);
        }
    }
    return values;
}

nlohmann::ordered_json metricsSpecJson(const MetricOptionsSpec& spec) {
    nlohmann::ordered_json regions = nlohmann::ordered_json::array();
    for (const RegionSpec& r : spec.regions) {
        nlohmann::ordered_json j = {{"name", r.name}};
        if (r.rect)
            j["rect"] = *r.rect;
        else
            j["indirect_fraction_above"] = r.indirectFractionAbove;
        regions.push_back(j);
    }
    nlohmann::ordered_json out = {
        {"ppd", spec.ppd}, {"exposure_ev", spec.exposureEv}, {"regions", regions}};
    // Only when on, so the identity (run key) of every run without it is unchanged.
    if (spec.sameVplReference) out["same_vpl_reference"] = true;
    return out;
}

ExperimentConfig parseExperimentConfig(const nlohmann::json& json, const std::string& context,
                                       const std::string& baseDir) {
    const JsonNode root(json, context);
    root.expectKeys({"name", "description", "scenes", "resolution", "reference", "timing",
                     "metrics", "shared", "techniques", "max_runs"});
    ExperimentConfig c;
    c.path = context;
    c.name = root["name"].string();
    // The name is the results folder under the output root: no "", ".", ".." or separators
    if (c.name.empty())
        root["name"].fail(
            "empty name (it names the results folder; empty would put the runs "
            "in the output root itself)");
    for (char ch : c.name)
        if (!(std::isalnum(static_cast<unsigned char>(ch)) || ch == '_' || ch == '-'))
            root["name"].fail("\"" + c.name +
                              "\": use letters, digits, '_' and '-' only (it names a folder)");
    if (root.has("max_runs")) c.maxRuns = size_t(root["max_runs"].integerIn(1, kMaxRunsCeiling));
    if (root.has("description")) c.description = root["description"].string();
    int w = 0, h = 0;
    if (root.has("resolution")) {
        const JsonNode r = root["resolution"];
        if (r.arraySize() != 2) r.fail("expected [width, height]");
        w = r.item(0).integerIn(1, 16384);
        h = r.item(1).integerIn(1, 16384);
    }
    const JsonNode scenes = root["scenes"];
    if (scenes.arraySize() == 0) scenes.fail("needs at least one scene");
    std::set<std::string> labels;
    for (size_t i = 0; i < scenes.arraySize(); ++i) {
        c.scenes.push_back(parseScene(scenes.item(i), baseDir, w, h));
        if (!labels.insert(c.scenes.back().label).second)
            scenes.item(i).fail("duplicate scene label \"" + c.scenes.back().label + "\"");
    }
    if (!root.has("reference")) root.fail("missing \"reference\" (the ground-truth settings)");
    c.reference = parseReference(root["reference"]);
    if (root.has("timing")) {
        const JsonNode t = root["timing"];
        t.expectKeys({"warmup", "frames", "target_iqr", "max_frames"});
        if (t.has("warmup")) c.timing.warmupFrames = t["warmup"].integerIn(0, 1000);
        if (t.has("frames")) c.timing.timedFrames = t["frames"].integerIn(1, 100000);
        if (t.has("target_iqr")) c.timing.targetIqr = t["target_iqr"].numberIn(0.0, 10.0);
        if (t.has("max_frames")) {
            c.timing.maxFrames = t["max_frames"].integerIn(1, 100000);
            if (c.timing.maxFrames < c.timing.timedFrames)
                t["max_frames"].fail("must be at least \"frames\" (" +
                                     std::to_string(c.timing.timedFrames) + ")");
        }
    }
    if (root.has("metrics")) c.metrics = parseMetrics(root["metrics"]);
    if (root.has("shared")) c.shared = parseAssignments(root["shared"], defaultSharedParams());
    const JsonNode techniques = root["techniques"];
    if (techniques.arraySize() == 0) techniques.fail("needs at least one technique");
    for (size_t i = 0; i < techniques.arraySize(); ++i)
        c.techniques.push_back(parseTechnique(techniques.item(i), labels));
    checkRunCount(c);  // before anything is expanded: a sweep may be astronomically large
    expandRuns(c);     // validates every combination (shared limits included) before anything runs
    return c;
}

ExperimentConfig loadExperimentConfig(const std::string& path) {
    // Duplicate keys, out-of-range numbers and syntax errors name the file, line and key
    const nlohmann::json json = readJsonFile(path, "experiment config");
    const std::string baseDir = fs::path(path).parent_path().string();
    return parseExperimentConfig(json, path, baseDir.empty() ? "." : baseDir);
}

size_t countRuns(const ExperimentConfig& config, size_t saturateAt) {
    // Saturating arithmetic: the product of many sweep axes overflows size_t easily
    const auto mul = [saturateAt](size_t a, size_t b) {
        size_t r = 0;
        return __builtin_mul_overflow(a, b, &r) || r > saturateAt ? saturateAt : r;
    };
    const auto add = [saturateAt](size_t a, size_t b) {
        size_t r = 0;
        return __builtin_add_overflow(a, b, &r) || r > saturateAt ? saturateAt : r;
    };
    size_t total = 0;
    for (const SceneEntry& scene : config.scenes)
        for (const TechniqueEntry& t : config.techniques) {
            if (!t.scenes.empty() &&
                std::find(t.scenes.begin(), t.scenes.end(), scene.label) == t.scenes.end())
                continue;
            size_t n = 1;
            for (const auto& [key, values] : t.grid)
                n = mul(n, values.size());
            if (!t.zip.empty()) n = mul(n, t.zip.front().second.size());
            total = add(total, mul(n, size_t(t.repeats)));
        }
    return total;
}

size_t planningMemoryBudget() {
    const long pages = sysconf(_SC_PHYS_PAGES), pageSize = sysconf(_SC_PAGESIZE);
    if (pages <= 0 || pageSize <= 0) return size_t(4) << 30;  // unknown: assume 16 GiB
    return size_t(pages) * size_t(pageSize) / 4;
}

void checkRunCount(const ExperimentConfig& config) {
    const size_t limit = config.maxRuns;
    const size_t count = countRuns(config, std::numeric_limits<size_t>::max());
    // Planning holds every run in memory (about 7 KiB a run measured by issue 31's reviewer;
    // more once the runner keys and records them): refuse what would not fit, with a message,
    // instead of dying later with std::bad_alloc.
    const size_t budget = planningMemoryBudget();
    if (count <= limit && count > budget / kPlanningBytesPerRun) {
        const auto gib = [](double bytes) {
            char text[32];
            std::snprintf(text, sizeof text, "%.1f GiB", bytes / double(size_t(1) << 30));
            return std::string(text);
        };
        throw Error(config.path + ": the sweeps expand to " + std::to_string(count) +
                    " runs, whose plan needs about " +
                    gib(double(count) * double(kPlanningBytesPerRun)) + " (" +
                    std::to_string(kPlanningBytesPerRun / 1024) +
                    " KiB a run), more than a quarter of this machine's memory (" +
                    gib(double(budget) * 4.0) + "); at most " +
                    std::to_string(budget / kPlanningBytesPerRun) +
                    " runs fit: shrink the sweeps or split the config into several");
    }
    if (count <= limit) return;
    const std::string countText = count == std::numeric_limits<size_t>::max()
                                      ? "more than " + std::to_string(count)
                                      : std::to_string(count);
    throw Error(config.path + ": the sweeps expand to " + countText +
                " runs (scenes x techniques x sweep points), more than the limit of " +
                std::to_string(limit) +
                "; shrink the sweeps, or raise the limit with \"max_runs\": " +
                (count <= kMaxRunsCeiling ? std::to_string(count)
                                          : "N (at most " + std::to_string(kMaxRunsCeiling) + ")") +
                " at the top level of the config (docs/experiments.md)");
}

std::vector<RunSpec> expandRuns(const ExperimentConfig& config) {
    checkRunCount(config);  // also for configs built in memory
    std::vector<RunSpec> runs, repeats;
    runs.reserve(countRuns(config, config.maxRuns));
    for (const SceneEntry& scene : config.scenes) {
        for (const TechniqueEntry& t : config.techniques) {
            if (!t.scenes.empty() &&
                std::find(t.scenes.begin(), t.scenes.end(), scene.label) == t.scenes.end())
                continue;
            ParamSet base = defaultRunParams(t.id);
            for (const auto& [k, v] : t.fixed)
                base.setJson(k, v);
            ParamSet shared = defaultSharedParams();
            for (const auto& [k, v] : config.shared)
                shared.setJson(k, v);
            for (const auto& [k, v] : t.shared)
                shared.setJson(k, v);
            try {
                (void)sharedSettingsFromParams(shared);
            } catch (const Error& e) {
                throw Error(config.path + ": technique \"" + t.id + "\": " + e.what());
            }

            // Grid: cartesian product; zip: lock-step; the two are combined as a product.
            std::vector<std::map<std::string, nlohmann::json>> points{{}};
            for (const auto& [key, values] : t.grid) {
                std::vector<std::map<std::string, nlohmann::json>> next;
                for (const auto& p : points)
                    for (const nlohmann::json& v : values) {
                        auto q = p;
                        q[key] = v;
                        next.push_back(std::move(q));
                    }
                points = std::move(next);
            }
            if (!t.zip.empty()) {
                std::vector<std::map<std::string, nlohmann::json>> next;
                for (const auto& p : points)
                    for (size_t i = 0; i < t.zip.front().second.size(); ++i) {
                        auto q = p;
                        for (const auto& [key, values] : t.zip)
                            q[key] = values[i];
                        next.push_back(std::move(q));
                    }
                points = std::move(next);
            }
            for (const auto& point : points) {
                RunSpec run;
                run.index = runs.size();
                run.scene = &scene;
                run.techniqueId = t.id;
                run.params = base;
                run.shared = shared;
                for (const auto& [k, v] : point) {
                    const AxisTarget target = axisTarget(k, run.params, run.shared);
                    target.params->setJson(target.key, v);
                    run.swept[k] = target.params->getText(target.key);
                }
                try {
                    (void)sharedSettingsFromParams(run.shared);
                } catch (const Error& e) {
                    throw Error(config.path + ": technique \"" + t.id + "\" " +
                                run.shared.toString() + ": " + e.what());
                }
                const TechniqueInfo* info =
                    t.id == kPathTracerId ? nullptr : &TechniqueRegistry::instance().get(t.id);
                if (info && info->checkParams) {
                    try {
                        info->checkParams(run.params);
                    } catch (const Error& e) {
                        throw Error(config.path + ": technique \"" + t.id + "\" " +
                                    run.params.toString() + ": " + e.what());
                    }
                }
                run.timedFrames = t.timedFrames;
                run.warmupFrames = t.warmupFrames;
                for (int r = 1; r < t.repeats; ++r) {  // after every block's first round
                    RunSpec again = run;
                    again.repeat = r;
                    repeats.push_back(std::move(again));
                }
                runs.push_back(std::move(run));
            }
        }
    }
    // Repeat rounds: round r holds every configuration's r-th repeat, in the first round's order
    std::stable_sort(repeats.begin(), repeats.end(),
                     [](const RunSpec& a, const RunSpec& b) { return a.repeat < b.repeat; });
    for (RunSpec& r : repeats) {
        r.index = runs.size();
        runs.push_back(std::move(r));
    }
    return runs;
}

}  // namespace gilab::exp
