// The audit's case catalog (experiments/configs/audit.json, docs/audit.md).
#include <filesystem>

#include "core/util/error.h"
#include "core/util/json_reader.h"
#include "experiments/audit/audit.h"

namespace gilab::audit {

namespace {

namespace fs = std::filesystem;

Profile parseProfile(const JsonNode& n) {
    n.expectKeys({"resolution", "spp", "max_bounces", "voxel_resolution", "warmup", "frames",
                  "cell_timeout_s"});
    Profile p;
    const JsonNode r = n["resolution"];
    if (r.arraySize() != 2) r.fail("expected [width, height]");
    p.width = r.item(0).integerIn(1, 4096);
    p.height = r.item(1).integerIn(1, 4096);
    p.spp = n["spp"].integerIn(1, 1 << 20);
    p.maxBounces = n["max_bounces"].integerIn(0, 1024);
    p.voxelResolution = n["voxel_resolution"].integerIn(1, 4096);
    p.warmupFrames = n.has("warmup") ? n["warmup"].integerIn(0, 100) : 1;
    p.frames = n.has("frames") ? n["frames"].integerIn(1, 100) : 1;
    p.cellTimeoutS = numberOr(n, "cell_timeout_s", 600.0);
    if (!(p.cellTimeoutS > 0.0)) n["cell_timeout_s"].fail("must be > 0");
    return p;
}

/** A parameter value as it would be typed after --set (16, 0.5, true, dense). */
std::string valueText(const JsonNode& v) {
    const nlohmann::json& raw = v.raw();
    if (raw.is_string()) return raw.get<std::string>();
    if (raw.is_boolean()) return raw.get<bool>() ? "true" : "false";
    if (raw.is_number()) {
        v.number();  // finite
        return raw.dump();
    }
    v.fail("expected a number, a string or a boolean");
}

std::map<std::string, std::map<std::string, std::string>> parseTechniqueParams(const JsonNode& n) {
    std::map<std::string, std::map<std::string, std::string>> out;
    if (!n.raw().is_object()) n.fail("expected {\"<technique>\": {\"<param>\": value}}");
    for (const auto& item : n.raw().items()) {
        const JsonNode params = n[item.key().c_str()];
        if (!params.raw().is_object()) params.fail("expected {\"<param>\": value}");
        auto& dst = out[item.key()];
        for (const auto& p : params.raw().items())
            dst[p.key()] = valueText(params[p.key().c_str()]);
    }
    return out;
}

std::string resolveScene(const JsonNode& n, const fs::path& base) {
    const std::string text = n.string();
    if (text == "builtin") return text;
    const size_t hash = text.find('#');
    const std::string file = text.substr(0, hash);
    const std::string variant = hash == std::string::npos ? "" : text.substr(hash);
    const fs::path p = fs::path(file).is_absolute() ? fs::path(file) : base / file;
    if (!fs::exists(p)) n.fail("no such scene file: " + p.lexically_normal().string());
    return p.lexically_normal().string() + variant;
}

}  // namespace

Catalog loadCatalog(const std::string& path) {
    const nlohmann::json json = readJsonFile(path, "audit catalog");
    const JsonNode root(json, path);
    root.expectKeys({"description", "profiles", "technique_params", "cases"});
    const fs::path base = fs::absolute(path).parent_path();
    Catalog c;
    c.path = path;
    const JsonNode profiles = root["profiles"];
    profiles.expectKeys({"quick", "full"});
    c.quick = parseProfile(profiles["quick"]);
    c.full = parseProfile(profiles["full"]);
    if (root.has("technique_params"))
        c.techniqueParams = parseTechniqueParams(root["technique_params"]);
    const JsonNode cases = root["cases"];
    if (cases.arraySize() == 0) cases.fail("no cases");
    std::map<std::string, int> seen;
    for (size_t i = 0; i < cases.arraySize(); ++i) {
        const JsonNode n = cases.item(i);
        n.expectKeys({"name", "what", "scene", "quick", "max_bounces", "roulette_start_bounce",
                      "params", "parameter_case", "leak_scale", "scale_group", "scale_base",
                      "scale_tolerance", "resolution", "documented_failure"});
        AuditCase a;
        a.name = n["name"].string();
        if (a.name.empty() ||
            a.name.find_first_not_of("abcdefghijklmnopqrstuvwxyz0123456789_") != std::string::npos)
            n["name"].fail("must be non-empty lower-case letters, digits and _");
        if (seen[a.name]++) n["name"].fail("duplicate case name \"" + a.name + "\"");
        a.what = n["what"].string();
        a.scene = resolveScene(n["scene"], base);
        a.quick = booleanOr(n, "quick", false);
        if (n.has("max_bounces")) a.maxBounces = n["max_bounces"].integerIn(0, 1024);
        if (n.has("roulette_start_bounce"))
            a.rouletteStart = n["roulette_start_bounce"].integerIn(-1, 1024);
        if (n.has("params")) a.params = parseTechniqueParams(n["params"]);
        a.parameterCase = booleanOr(n, "parameter_case", false);
        if (a.parameterCase && a.params.empty())
            n.fail("a parameter case needs \"params\" for at least one technique");
        if (n.has("leak_scale")) a.leakScale = resolveScene(n["leak_scale"], base);
        if (n.has("documented_failure")) a.documentedFailure = n["documented_failure"].string();
        if (n.has("scale_group")) a.scaleGroup = n["scale_group"].string();
        a.scaleBase = booleanOr(n, "scale_base", false);
        if (a.scaleBase && a.scaleGroup.empty()) n["scale_base"].fail("needs \"scale_group\"");
        if (n.has("resolution")) {
            const JsonNode r = n["resolution"];
            if (r.arraySize() != 2) r.fail("expected [width, height]");
            a.resolution = glm::ivec2(r.item(0).integerIn(1, 4096), r.item(1).integerIn(1, 4096));
        }
        if (n.has("scale_tolerance")) {
            a.scaleTolerance = n["scale_tolerance"].numberIn(1e-6, 0.1);
            if (a.scaleGroup.empty()) n["scale_tolerance"].fail("needs \"scale_group\"");
        }
        c.cases.push_back(std::move(a));
    }
    std::map<std::string, int> bases;
    for (const AuditCase& a : c.cases)
        if (!a.scaleGroup.empty()) bases[a.scaleGroup] += a.scaleBase ? 1 : 0;
    for (const auto& [group, count] : bases)
        if (count != 1)
            throw Error(path + ": scale group \"" + group + "\" needs exactly one case with " +
                        "\"scale_base\": true (has " + std::to_string(count) + ")");
    return c;
}

}  // namespace gilab::audit
