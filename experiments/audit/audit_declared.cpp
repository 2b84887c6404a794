// A technique's declared weaknesses (docs/audit.md, "Declared weaknesses"): the audit cases it is
// expected to fail and why, from its folder's known_weaknesses.json, embedded at build time.
#include <nlohmann/json.hpp>

#include "core/util/embedded_text.h"
#include "core/util/error.h"
#include "experiments/audit/audit.h"

namespace gilab::audit {

std::map<std::string, std::string> declaredWeaknesses(const std::string& technique) {
    const std::string name = technique + "/known_weaknesses.json";
    const std::optional<std::string> text = embeddedText(name);
    if (!text) return {};
    const std::string where = name + " (the technique folder's known_weaknesses.json)";
    nlohmann::json j;
    try {
        j = nlohmann::json::parse(*text);
    } catch (const nlohmann::json::parse_error& e) {
        throw Error(where + ": not valid JSON: " + e.what());
    }
    if (!j.is_object()) throw Error(where + ": expected an object {\"cases\": {...}}");
    for (const auto& [key, value] : j.items())
        if (key != "cases" && key != "comment")
            throw Error(where + ": unknown key \"" + key + "\" (allowed: cases, comment)");
    if (!j.contains("cases") || !j["cases"].is_object())
        throw Error(where + ": \"cases\" must be an object of audit case -> why");
    std::map<std::string, std::string> out;
    for (const auto& [caseName, why] : j["cases"].items()) {
        if (!why.is_string() || why.get<std::string>().empty())
            throw Error(where + ": case \"" + caseName +
                        "\": the value must say why the technique fails it (a non-empty string)");
        out[caseName] = why.get<std::string>();
    }
    return out;
}

}  // namespace gilab::audit
