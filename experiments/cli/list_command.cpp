// `gilab list`: every registered technique with its parameter table, and the shared passes'.
#include <cstdio>

#include <nlohmann/json.hpp>

#include "core/technique/frame_harness.h"
#include "core/technique/registry.h"
#include "experiments/cli/cli.h"

namespace gilab::cli {
namespace {

const char* bouncesText(int bounces) {
    static thread_local char buf[32];
    if (bounces == kAllBounces) return "all";
    std::snprintf(buf, sizeof buf, "%d", bounces);
    return buf;
}

std::string supportText(const FeatureSupport& s) {
    std::string out;
    auto add = [&](bool on, const char* what) {
        if (on) out += (out.empty() ? "" : ", ") + std::string(what);
    };
    add(s.pointLights, "point");
    add(s.spotLights, "spot");
    add(s.directionalLights, "directional");
    add(s.emissiveSurfaces, "emissive surfaces");
    return out;
}

nlohmann::ordered_json specsToJson(const std::vector<ParamSpec>& specs) {
    nlohmann::ordered_json out = nlohmann::ordered_json::array();
    for (const ParamSpec& s : specs) {
        out.push_back({{"name", s.name},
                       {"type", paramTypeName(s.type)},
                       {"default", s.defaultValue},
                       {"range", describeParamRange(s)},
                       {"power_of_two", s.powerOfTwo},
                       {"odd", s.odd},
                       {"also_allowed", s.alsoAllowed},
                       {"cross_rule", s.crossRule},
                       {"unit", s.unit},
                       {"stage", paramStageName(s.stage)},
                       {"help", s.help}});
    }
    return out;
}

}  // namespace

int runList(bool json) {
    const auto techniques = TechniqueRegistry::instance().list();
    const auto shared = sharedPassParamSpecs();
    if (json) {
        nlohmann::ordered_json out;
        for (const TechniqueInfo* t : techniques) {
            out["techniques"].push_back({{"id", t->id},
                                         {"description", t->description},
                                         {"citation", t->citation},
                                         {"indirect_bounces", t->indirectBounces},
                                         {"supports", supportText(t->supports)},
                                         {"origin", TechniqueRegistry::instance().origin(t->id)},
                                         {"params", specsToJson(t->params)}});
        }
        out["shared"] = specsToJson(shared);
        std::printf("%s\n", out.dump(2).c_str());
        return kExitOk;
    }
    for (const TechniqueInfo* t : techniques) {
        std::printf("%s — %s\n", t->id.c_str(), t->description.c_str());
        if (!t->citation.empty()) std::printf("  paper: %s\n", t->citation.c_str());
        std::printf("  from: %s\n", TechniqueRegistry::instance().origin(t->id).c_str());
        std::printf("  indirect bounces: %s; lights: %s\n", bouncesText(t->indirectBounces),
                    supportText(t->supports).c_str());
        if (t->params.empty())
            std::printf("  parameters: none of its own (the shared passes' apply)\n\n");
        else
            std::printf("  parameters (--set key=value):\n%s\n",
                        formatParamHelp(t->params).c_str());
    }
    std::printf(
        "shared passes (G-buffer, shadow maps, direct light; every technique) — "
        "--set shared.key=value:\n%s",
        formatParamHelp(shared).c_str());
    return kExitOk;
}

}  // namespace gilab::cli
