#include "experiments/runner/run_metadata.h"

#include <unistd.h>
#include <limits>

#include <algorithm>
#include <cmath>
#include <ctime>
#include <fstream>
#include <map>
#include <thread>

#include "core/util/build_info.h"
#include "core/util/file_lock.h"
#include "core/util/stats.h"
#include "core/vk/context.h"

namespace gilab::cli {
namespace {

std::string cpuModel() {
    std::ifstream in("/proc/cpuinfo");
    std::string line;
    while (std::getline(in, line)) {
        if (line.rfind("model name", 0) == 0) {
            const size_t colon = line.find(':');
            if (colon != std::string::npos) return line.substr(colon + 2);
        }
    }
    return "unknown";
}

nlohmann::ordered_json vec3Json(const glm::vec3& v) {
    return {v.x, v.y, v.z};
}

/** NaN is not valid JSON: a NaN measurement is written as null. */
nlohmann::ordered_json number(double v) {
    return std::isfinite(v) ? nlohmann::ordered_json(v) : nlohmann::ordered_json(nullptr);
}

/**
 * Sum of a frame's pass times without double counting (diagnostic passes left out): a nested
 * pass is named
 * "<parent>.<child>" (e.g. "vct/inject.splat" inside "vct/inject") and is left out when its
 * parent is in the list; "shadow_maps.update" has no parent "shadow_maps" there and counts.
 */
double topLevelGpuMs(const std::vector<const vk::PassTime*>& passes) {
    double total = 0.0;
    for (const vk::PassTime* p : passes) {
        if (isDiagnosticPass(p->name)) continue;
        const size_t dot = p->name.rfind('.');
        const bool nested = dot != std::string::npos &&
                            std::any_of(passes.begin(), passes.end(), [&](const vk::PassTime* q) {
                                return q->name == p->name.substr(0, dot);
                            });
        if (!nested) total += p->gpuMs;
    }
    return total;
}

}  // namespace

nlohmann::ordered_json summaryJson(const std::vector<double>& values) {
    const Summary s = summarize(values);
    return {{"median", number(s.median)}, {"q1", number(s.q1)},   {"q3", number(s.q3)},
            {"iqr", number(s.iqr())},     {"min", number(s.min)}, {"max", number(s.max)},
            {"samples", values}};
}

bool isDiagnosticPass(const std::string& name) {
    const size_t slash = name.find('/');
    return name.compare(slash == std::string::npos ? 0 : slash + 1, 5, "diag.") == 0;
}

double frameGpuIqrOverMedian(const std::vector<FrameTiming>& frames) {
    if (frames.size() < 4) return std::numeric_limits<double>::quiet_NaN();
    std::vector<double> total;
    for (const FrameTiming& f : frames) {
        std::vector<const vk::PassTime*> list;
        for (const vk::PassTime& p : f.passes)
            list.push_back(&p);
        total.push_back(topLevelGpuMs(list));
    }
    const Summary s = summarize(total);
    return s.median > 0.0 ? s.iqr() / s.median : std::numeric_limits<double>::quiet_NaN();
}

std::string isoDateUtc() {
    const std::time_t now = std::time(nullptr);
    std::tm tm{};
    gmtime_r(&now, &tm);
    char buf[32];
    std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
    return buf;
}

nlohmann::ordered_json provenanceJson(const std::string& commandLine) {
    return {{"gilab_version", build::kVersion},
            {"git_commit", build::kGitCommit},
            {"build_type", build::kBuildType},
            {"compiler", build::kCompiler},
            {"date", isoDateUtc()},
            {"host", hostName()},
            {"cpu", cpuModel()},
            {"hardware_threads", std::thread::hardware_concurrency()},
            {"command_line", commandLine}};
}

nlohmann::ordered_json deviceJson(const vk::Context& ctx) {
    nlohmann::ordered_json candidates = nlohmann::ordered_json::array();
    for (const vk::DeviceCandidate& c : ctx.candidates())
        candidates.push_back({{"name", c.name}, {"chosen", c.chosen}, {"reason", c.reason}});
    return {{"name", ctx.deviceName()},
            {"type", ctx.deviceType()},
            {"driver", ctx.driverName()},
            {"driver_info", ctx.driverInfo()},
            {"vulkan_api", ctx.apiVersion()},
            {"validation", ctx.validationEnabled()},
            {"extensions", ctx.enabledExtensions()},
            {"candidates", candidates}};
}

nlohmann::ordered_json takeValidationJson(vk::Context& ctx) {
    nlohmann::ordered_json json = {{"enabled", ctx.validationEnabled()},
                                   {"errors", ctx.validationErrorCount()},
                                   {"warnings", ctx.validationWarningCount()},
                                   {"messages", ctx.validationMessages()}};
    ctx.clearValidationMessages();
    return json;
}

uint32_t validationMessageCount(const nlohmann::ordered_json& validation) {
    auto count = [&](const char* key) {
        const auto it = validation.find(key);  // end() when not an object
        const bool counted = it != validation.end() && it->is_number_integer() && *it >= 0;
        return counted ? it->get<uint32_t>() : 0u;
    };
    return count("errors") + count("warnings");
}

nlohmann::ordered_json sceneToJson(const Scene& scene) {
    const SceneCaps& c = scene.caps;
    nlohmann::ordered_json features = nlohmann::ordered_json::array();
    auto add = [&](bool on, const char* name) {
        if (on) features.push_back(name);
    };
    add(c.hasEmissive, "emissive");
    add(c.hasGlossy, "glossy");
    add(c.hasTextures, "textures");
    add(c.hasAlphaMask, "alpha_mask");
    add(c.hasPointLights, "point_lights");
    add(c.hasSpotLights, "spot_lights");
    add(c.hasDirectionalLights, "directional_lights");
    const char* kLightTypes[] = {"point", "spot", "directional"};
    nlohmann::ordered_json lights = nlohmann::ordered_json::array();
    for (const Light& l : scene.lights) {
        lights.push_back({{"name", l.name},
                          {"type", kLightTypes[int(l.type)]},
                          {"position", vec3Json(l.position)},
                          {"direction", vec3Json(l.direction)},
                          {"intensity", vec3Json(l.intensity)},
                          {"inner_cone_rad", l.innerConeRad},
                          {"outer_cone_rad", l.outerConeRad}});
    }
    nlohmann::ordered_json out = {{"name", scene.name},
                                  {"source", scene.sourcePath},
                                  {"files", scene.loadedFiles},
                                  {"resolution", {scene.settings.width, scene.settings.height}},
                                  {"exposure_ev", scene.settings.exposureEv},
                                  {"camera",
                                   {{"position", vec3Json(scene.camera.position)},
                                    {"target", vec3Json(scene.camera.target)},
                                    {"up", vec3Json(scene.camera.up)},
                                    {"vfov_deg", scene.camera.vfovRad * 180.0 / M_PI}}},
                                  {"lights", lights},
                                  {"caps",
                                   {{"triangles", c.triangleCount},
                                    {"emissive_triangles", c.emissiveTriangleCount},
                                    {"materials", scene.materials.size()},
                                    {"textures", scene.textures.size()},
                                    {"features", features},
                                    {"bounds_min", vec3Json(c.bounds.lo)},
                                    {"bounds_max", vec3Json(c.bounds.hi)}}},
                                  {"warnings", scene.warnings}};
    // Only animated scenes get the key, so static scenes describe (and identify) as before.
    if (scene.animation.animated()) {
        const SceneAnimation& a = scene.animation;
        nlohmann::ordered_json tracks = nlohmann::ordered_json::array();
        for (const AnimationTrack& t : a.tracks) {
            nlohmann::ordered_json keys = nlohmann::ordered_json::array();
            for (const AnimationKey& k : t.keys) {
                if (animationPropertyIsScalar(t.property))
                    keys.push_back({k.time, k.value.x});
                else
                    keys.push_back({k.time, vec3Json(k.value)});
            }
            tracks.push_back(
                {{"target", animationTarget(t)},
                 {"interpolation", t.interpolation == Interpolation::Slerp ? "slerp" : "linear"},
                 {"keys", keys}});
        }
        out["animation"] = {
            {"frames", a.frameCount}, {"duration_s", a.duration}, {"tracks", tracks}};
    }
    return out;
}

nlohmann::ordered_json timingJson(const SetupTiming& setup, const std::vector<FrameTiming>& frames,
                                  const WarmupResult& warmup) {
    std::vector<double> cpu;
    std::vector<std::string> order;
    std::map<std::string, std::vector<double>> gpu, record;
    for (const FrameTiming& f : frames) {
        cpu.push_back(f.cpuMs);
        for (const vk::PassTime& p : f.passes) {
            if (!gpu.count(p.name)) order.push_back(p.name);
            gpu[p.name].push_back(p.gpuMs);
            record[p.name].push_back(p.cpuRecordMs);
        }
    }
    nlohmann::ordered_json setupPasses = nlohmann::ordered_json::array();
    for (const vk::PassTime& p : setup.passes)
        setupPasses.push_back({{"name", p.name}, {"gpu_ms", number(p.gpuMs)}});
    nlohmann::ordered_json setupCpuPasses = nlohmann::ordered_json::array();
    for (const auto& [name, ms] : setup.cpuPasses)
        setupCpuPasses.push_back({{"name", name}, {"cpu_ms", number(ms)}});
    nlohmann::ordered_json passes = nlohmann::ordered_json::array();
    std::vector<double> gpuTotal(frames.size(), 0.0);
    for (const std::string& name : order) {
        passes.push_back({{"name", name},
                          {"gpu_ms", summaryJson(gpu[name])},
                          {"cpu_record_ms", summaryJson(record[name])}});
    }
    for (size_t i = 0; i < frames.size(); ++i) {
        std::vector<const vk::PassTime*> list;
        for (const vk::PassTime& p : frames[i].passes)
            list.push_back(&p);
        gpuTotal[i] = topLevelGpuMs(list);
    }
    return {{"policy", "docs/timing.md: warm-up discarded; median and IQR over timed frames"},
            {"setup_ms",
             {{"scene_upload", setup.sceneUploadMs},
              {"shared_passes", setup.sharedSetupMs},
              {"shadow_maps", setup.shadowMapsMs},
              {"technique", setup.techniqueSetupMs},
              {"total", setup.totalMs}}},
            {"setup_gpu_passes", setupPasses},
            {"setup_cpu_passes", setupCpuPasses},
            {"warmup_frames", warmup.requested},
            {"warmup_frames_run", warmup.run},
            {"warmup_settled", warmup.settled},
            {"timed_frames", frames.size()},
            {"frame_cpu_ms", summaryJson(cpu)},
            {"frame_gpu_ms", summaryJson(gpuTotal)},
            {"passes", passes}};
}

nlohmann::ordered_json dynamicTimingJson(const std::vector<FrameTiming>& frames) {
    std::vector<double> cpu, gpu, update, shared, own;
    std::vector<std::string> order;
    std::map<std::string, std::vector<double>> passes;
    for (const FrameTiming& f : frames) {
        if (!f.dynamic) continue;
        cpu.push_back(f.cpuMs);
        update.push_back(f.updateCpuMs);
        // Shared passes (G-buffer, shadow maps and cascades, direct light: names without a
        // technique prefix) apart from the technique's own "<id>/..." passes (issue 43).
        std::vector<const vk::PassTime*> all, sharedPasses, ownPasses;
        for (const std::vector<vk::PassTime>* list : {&f.passes, &f.updatePasses})
            for (const vk::PassTime& p : *list) {
                all.push_back(&p);
                (p.name.find('/') == std::string::npos ? sharedPasses : ownPasses).push_back(&p);
            }
        gpu.push_back(topLevelGpuMs(all));
        shared.push_back(topLevelGpuMs(sharedPasses));
        own.push_back(topLevelGpuMs(ownPasses));
        // Update passes may repeat a name (one submission per light): summed per frame.
        std::map<std::string, double> perFrame;
        for (const vk::PassTime& p : f.updatePasses) {
            if (!perFrame.count(p.name) && !passes.count(p.name)) order.push_back(p.name);
            perFrame[p.name] += p.gpuMs;
        }
        for (const auto& [name, ms] : perFrame)
            passes[name].push_back(ms);
    }
    nlohmann::ordered_json list = nlohmann::ordered_json::array();
    for (const std::string& name : order)
        list.push_back({{"name", name}, {"gpu_ms", summaryJson(passes[name])}});
    return {{"dynamic_frames", cpu.size()},
            {"dynamic_frame_cpu_ms", summaryJson(cpu)},
            {"dynamic_frame_gpu_ms", summaryJson(gpu)},
            {"dynamic_frame_shared_gpu_ms", summaryJson(shared)},
            {"dynamic_frame_technique_gpu_ms", summaryJson(own)},
            {"update_cpu_ms", summaryJson(update)},
            {"update_passes", list}};
}

nlohmann::ordered_json memoryJson(const MemoryReport& memory) {
    nlohmann::ordered_json owners, tags;
    for (const auto& [name, bytes] : memory.byOwner)
        owners[name] = bytes;
    for (const auto& [name, bytes] : memory.byTag)
        tags[name] = bytes;
    return {{"total_bytes", memory.totalBytes},
            {"peak_bytes", memory.peakBytes},
            {"by_owner", owners},
            {"by_resource", tags}};
}

bool isRadianceLayer(const std::string& name) {
    return name == "final" || name == "indirect" || name == "direct" || name == "emission" ||
           name == "albedo";
}

nlohmann::ordered_json finiteJson(const std::vector<ImageLayer>& layers, size_t* nonFinite) {
    nlohmann::ordered_json out;
    size_t total = 0;
    for (const ImageLayer& layer : layers) {
        const FiniteStats s = countNonFinite(layer.image);
        out[layer.name] = {{"nan_pixels", s.nanPixels},
                           {"inf_pixels", s.infPixels},
                           {"negative_pixels", s.negativePixels}};
        total += s.nanPixels + s.infPixels;
        // Radiance and albedo must not be negative (normals and signed debug views may be).
        if (isRadianceLayer(layer.name)) total += s.negativePixels;
    }
    if (nonFinite) *nonFinite = total;
    return out;
}

}  // namespace gilab::cli
