// Spec-table helpers, help text and "key=value" splitting.
#include <algorithm>
#include <cmath>

#include "core/params/params.h"
#include "core/util/error.h"
#include "core/util/strings.h"

namespace gilab {

ParamSpec boolParam(std::string name, bool def, std::string help, ParamStage stage) {
    ParamSpec spec;
    spec.name = std::move(name);
    spec.type = ParamType::Bool;
    spec.defaultValue = def ? "true" : "false";
    spec.help = std::move(help);
    spec.stage = stage;
    return spec;
}

ParamSpec intParam(std::string name, int def, double minValue, double maxValue, std::string unit,
                   std::string help, ParamStage stage) {
    ParamSpec spec;
    spec.name = std::move(name);
    spec.type = ParamType::Int;
    spec.defaultValue = std::to_string(def);
    spec.minValue = minValue;
    spec.maxValue = maxValue;
    spec.unit = std::move(unit);
    spec.help = std::move(help);
    spec.stage = stage;
    return spec;
}

ParamSpec floatParam(std::string name, double def, double minValue, double maxValue,
                     std::string unit, std::string help, ParamStage stage) {
    ParamSpec spec;
    spec.name = std::move(name);
    spec.type = ParamType::Float;
    spec.defaultValue = formatShortest(def);
    spec.minValue = minValue;
    spec.maxValue = maxValue;
    spec.unit = std::move(unit);
    spec.help = std::move(help);
    spec.stage = stage;
    return spec;
}

ParamSpec enumParam(std::string name, std::string def, std::vector<std::string> choices,
                    std::string help, ParamStage stage) {
    ParamSpec spec;
    spec.name = std::move(name);
    spec.type = ParamType::Enum;
    spec.defaultValue = std::move(def);
    spec.choices = std::move(choices);
    spec.help = std::move(help);
    spec.stage = stage;
    return spec;
}

const char* paramTypeName(ParamType type) {
    switch (type) {
        case ParamType::Bool:
            return "bool";
        case ParamType::Int:
            return "int";
        case ParamType::Float:
            return "float";
        case ParamType::Enum:
            return "enum";
    }
    return "?";
}

const char* paramStageName(ParamStage stage) {
    return stage == ParamStage::Rebuild ? "rebuild" : "per-frame";
}

namespace {

/** The numeric range alone: "[a, b]", "a" (a == b), ">= a", "<= b" or "any". */
std::string rangeText(const ParamSpec& spec) {
    const bool hasMin = std::isfinite(spec.minValue);
    const bool hasMax = std::isfinite(spec.maxValue);
    // Built by appending: GCC 12 warns falsely (-Wrestrict) on "literal" + std::string&&.
    std::string out;
    if (hasMin && hasMax && spec.minValue == spec.maxValue) {
        out = formatShortest(spec.minValue);
    } else if (hasMin && hasMax) {
        out.append("[").append(formatShortest(spec.minValue)).append(", ");
        out.append(formatShortest(spec.maxValue)).append("]");
    } else if (hasMin) {
        out.append(">= ").append(formatShortest(spec.minValue));
    } else if (hasMax) {
        out.append("<= ").append(formatShortest(spec.maxValue));
    } else {
        out = "any";
    }
    return out;
}

/** Int/Float values in words; `sentence` reads after "must be" ("in [1, 2]", "a power of two"). */
std::string describeNumbers(const ParamSpec& spec, bool sentence) {
    const std::string range = rangeText(spec);
    const bool interval = range.front() == '[';
    const std::string rule = spec.powerOfTwo ? "power of two" : spec.odd ? "odd" : "";
    std::string out;
    if (rule.empty()) {
        out = sentence && interval ? "in " + range : range;
    } else {
        out = sentence && spec.powerOfTwo ? "a " + rule : rule;
        if (range != "any") out.append(interval ? " in " : " ").append(range);
    }
    for (auto it = spec.alsoAllowed.rbegin(); it != spec.alsoAllowed.rend(); ++it)
        out = formatShortest(*it) + " or " + out;
    return out;
}

}  // namespace

ParamSpec requirePowerOfTwo(ParamSpec spec) {
    spec.powerOfTwo = true;
    return spec;
}

ParamSpec requireOdd(ParamSpec spec) {
    spec.odd = true;
    return spec;
}

ParamSpec allowValue(double value, ParamSpec spec) {
    spec.alsoAllowed.push_back(value);
    return spec;
}

ParamSpec addCrossRule(std::string rule, ParamSpec spec) {
    spec.crossRule = std::move(rule);
    return spec;
}

std::string describeParamRange(const ParamSpec& spec) {
    std::string out;
    switch (spec.type) {
        case ParamType::Bool:
            out = "true|false";
            break;
        case ParamType::Enum:
            out = joinStrings(spec.choices, "|");
            break;
        case ParamType::Int:
        case ParamType::Float:
            out = describeNumbers(spec, false);
            break;
    }
    if (!spec.crossRule.empty()) out.append("; ").append(spec.crossRule);
    return out;
}

std::string describeAllowedValues(const ParamSpec& spec) {
    if (spec.type == ParamType::Int || spec.type == ParamType::Float)
        return describeNumbers(spec, true);
    return describeParamRange(spec);
}

std::string formatParamHelp(const std::vector<ParamSpec>& specs) {
    std::vector<std::vector<std::string>> rows;
    rows.push_back({"name", "type", "default", "range", "unit", "stage", "help"});
    for (const ParamSpec& spec : specs) {
        rows.push_back({spec.name, paramTypeName(spec.type), spec.defaultValue,
                        describeParamRange(spec), spec.unit, paramStageName(spec.stage),
                        spec.help});
    }
    std::vector<size_t> widths(rows[0].size(), 0);
    for (const auto& row : rows) {
        for (size_t c = 0; c < row.size(); ++c)
            widths[c] = std::max(widths[c], row[c].size());
    }
    std::string out;
    for (const auto& row : rows) {
        std::string line;
        for (size_t c = 0; c < row.size(); ++c) {
            line += row[c];
            if (c + 1 < row.size()) line += std::string(widths[c] - row[c].size() + 2, ' ');
        }
        out += trimString(line) + "\n";
    }
    return out;
}

std::pair<std::string, std::string> splitAssignment(const std::string& text) {
    const size_t eq = text.find('=');
    if (eq == std::string::npos) throw Error("expected key=value, got '" + text + "'");
    std::string key = trimString(std::string_view(text).substr(0, eq));
    std::string value = trimString(std::string_view(text).substr(eq + 1));
    if (key.empty()) throw Error("missing key before '=' in '" + text + "'");
    if (value.empty()) throw Error("missing value after '=' in '" + text + "'");
    return {key, value};
}

}  // namespace gilab
