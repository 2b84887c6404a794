// ParamSet: strict parsing, validation and typed access.
#include "core/params/params.h"

#include <charconv>
#include <cmath>
#include <limits>
#include <optional>

#include "core/util/error.h"
#include "core/util/strings.h"

namespace gilab {

namespace {

using Value = std::variant<bool, int, double, std::string>;

/** A parsed value, or the reason it was rejected ("expects an integer, got '1.5'"). */
struct Parsed {
    std::optional<Value> value;
    std::string reason;
};

Parsed reject(std::string reason) {
    return {std::nullopt, std::move(reason)};
}

std::string inQuotes(const std::string& text) {
    return "'" + text + "'";
}

/** Empty if `v` is allowed (an extra value, or inside the inclusive range and obeying the
 *  power-of-two and odd rules), else the reason. */
std::string checkRange(const ParamSpec& spec, double v, const std::string& text) {
    for (double allowed : spec.alsoAllowed)
        if (v == allowed) return "";
    const bool inRange = v >= spec.minValue && v <= spec.maxValue;
    bool rulesOk = true;
    if (spec.powerOfTwo || spec.odd) {  // Int only (checkSpec), so v holds an int
        const long long n = (long long)v;
        rulesOk = spec.powerOfTwo ? n > 0 && (n & (n - 1)) == 0 : n % 2 != 0;
    }
    if (inRange && rulesOk) return "";
    return "must be " + describeAllowedValues(spec) + ", got " + text;
}

Parsed parseBool(const std::string& text) {
    const std::string lower = toLowerAscii(text);
    if (lower == "true" || lower == "1" || lower == "on") return {Value(true), ""};
    if (lower == "false" || lower == "0" || lower == "off") return {Value(false), ""};
    return reject("expects a boolean (true/false/1/0/on/off), got " + inQuotes(text));
}

Parsed parseInt(const ParamSpec& spec, const std::string& text) {
    // Strict: optional sign, then decimal digits only.
    size_t start = (!text.empty() && (text[0] == '+' || text[0] == '-')) ? 1 : 0;
    bool digits = text.size() > start;
    for (size_t i = start; i < text.size(); ++i)
        digits = digits && text[i] >= '0' && text[i] <= '9';
    if (!digits) return reject("expects an integer, got " + inQuotes(text));
    const char* first = text.data() + (text[0] == '+' ? 1 : 0);
    long long v = 0;
    auto [end, ec] = std::from_chars(first, text.data() + text.size(), v);
    constexpr long long kMin = std::numeric_limits<int>::min();
    constexpr long long kMax = std::numeric_limits<int>::max();
    if (ec != std::errc() || end != text.data() + text.size() || v < kMin || v > kMax) {
        return reject("expects a 32-bit integer, got " + inQuotes(text));
    }
    if (std::string why = checkRange(spec, double(v), text); !why.empty()) return reject(why);
    return {Value(int(v)), ""};
}

Parsed parseFloat(const ParamSpec& spec, const std::string& text) {
    const char* first = text.data();
    const char* last = text.data() + text.size();
    if (first != last && *first == '+' && last - first > 1 && first[1] != '-') ++first;
    double v = 0.0;
    auto [end, ec] = std::from_chars(first, last, v, std::chars_format::general);
    if (first == last || ec == std::errc::invalid_argument || end != last) {
        return reject("expects a number, got " + inQuotes(text));
    }
    if (ec == std::errc::result_out_of_range || !std::isfinite(v) ||
        std::fabs(v) > double(std::numeric_limits<float>::max())) {
        return reject("expects a finite number in float range, got " + inQuotes(text));
    }
    if (std::string why = checkRange(spec, v, text); !why.empty()) return reject(why);
    return {Value(v), ""};
}

Parsed parseEnum(const ParamSpec& spec, const std::string& text) {
    for (const std::string& choice : spec.choices) {
        if (choice == text) return {Value(choice), ""};
    }
    std::string reason =
        "must be one of {" + joinStrings(spec.choices, ", ") + "}, got " + inQuotes(text);
    std::string closest = findClosestMatch(text, spec.choices);
    if (!closest.empty()) reason += " (did you mean " + inQuotes(closest) + "?)";
    return reject(reason);
}

Parsed parseValue(const ParamSpec& spec, const std::string& rawText) {
    const std::string text = trimString(rawText);
    switch (spec.type) {
        case ParamType::Bool:
            return parseBool(text);
        case ParamType::Int:
            return parseInt(spec, text);
        case ParamType::Float:
            return parseFloat(spec, text);
        case ParamType::Enum:
            return parseEnum(spec, text);
    }
    return reject("has an unknown type");
}

std::string canonicalText(const Value& value) {
    if (const bool* b = std::get_if<bool>(&value)) return *b ? "true" : "false";
    if (const int* i = std::get_if<int>(&value)) return std::to_string(*i);
    if (const double* d = std::get_if<double>(&value)) return formatShortest(*d);
    return std::get<std::string>(value);
}

bool isSnakeCase(const std::string& name) {
    if (name.empty() || name[0] < 'a' || name[0] > 'z') return false;
    for (char c : name) {
        if (!((c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_')) return false;
    }
    return true;
}

/** Empty if the spec is self-consistent (apart from its default), else the reason. */
std::string checkSpec(const ParamSpec& spec) {
    if (!isSnakeCase(spec.name)) return "name is not snake_case";
    if (std::isnan(spec.minValue) || std::isnan(spec.maxValue)) return "range has a NaN bound";
    if (spec.minValue > spec.maxValue) return "range is empty (min > max)";
    if (spec.type == ParamType::Enum) {
        if (spec.choices.empty()) return "enum has no choices";
        for (size_t i = 0; i < spec.choices.size(); ++i) {
            const std::string& c = spec.choices[i];
            if (c.empty() || trimString(c) != c || c.find_first_of(" =") != std::string::npos) {
                return "choice " + inQuotes(c) + " is empty or has spaces or '='";
            }
            for (size_t j = 0; j < i; ++j) {
                if (spec.choices[j] == c) return "choice " + inQuotes(c) + " appears twice";
            }
        }
    } else if (!spec.choices.empty()) {
        return "only enum parameters have choices";
    }
    if (spec.type != ParamType::Int && (spec.powerOfTwo || spec.odd))
        return "only int parameters can be a power of two or odd";
    if (spec.powerOfTwo && spec.odd) return "a power of two and odd leaves only 1";
    if (!spec.alsoAllowed.empty() && spec.type != ParamType::Int && spec.type != ParamType::Float)
        return "only int and float parameters have extra allowed values";
    for (double v : spec.alsoAllowed)
        if (!std::isfinite(v) || (spec.type == ParamType::Int && v != std::floor(v)))
            return "extra allowed value " + formatShortest(v) + " is not a finite " +
                   paramTypeName(spec.type);
    if (spec.type == ParamType::Int) {
        for (double bound : {spec.minValue, spec.maxValue}) {
            if (std::isfinite(bound) && bound != std::floor(bound)) {
                return "int range bound " + formatShortest(bound) + " is not an integer";
            }
        }
    }
    return "";
}

}  // namespace

ParamSet::ParamSet(std::vector<ParamSpec> specs, std::string owner)
    : m_specs(std::make_shared<const std::vector<ParamSpec>>(std::move(specs))),
      m_owner(std::move(owner)) {
    for (size_t i = 0; i < table().size(); ++i) {
        const ParamSpec& spec = table()[i];
        const std::string what = prefix() + "parameter spec " + inQuotes(spec.name) + " ";
        if (std::string why = checkSpec(spec); !why.empty())
            throw Error(what + "is invalid: " + why);
        for (size_t j = 0; j < i; ++j) {
            if (table()[j].name == spec.name) throw Error(what + "is declared twice");
        }
        Parsed parsed = parseValue(spec, spec.defaultValue);
        if (!parsed.value) throw Error(what + "is invalid: default value " + parsed.reason);
        m_values.push_back(std::move(*parsed.value));
    }
}

std::string ParamSet::prefix() const {
    return m_owner.empty() ? "" : m_owner + ": ";
}

int ParamSet::findIndex(const std::string& key) const {
    for (size_t i = 0; i < table().size(); ++i) {
        if (table()[i].name == key) return int(i);
    }
    return -1;
}

size_t ParamSet::requireKnownKey(const std::string& key) const {
    const int index = findIndex(key);
    if (index >= 0) return size_t(index);
    if (table().empty())
        throw Error(prefix() + "unknown parameter " + inQuotes(key) + "; there are no parameters");
    std::vector<std::string> names;
    for (const ParamSpec& spec : table())
        names.push_back(spec.name);
    std::string message = prefix() + "unknown parameter " + inQuotes(key);
    std::string closest = findClosestMatch(key, names);
    if (!closest.empty()) message += " (did you mean " + inQuotes(closest) + "?)";
    throw Error(message + "; valid parameters: " + joinStrings(names, ", "));
}

const ParamSet::Value& ParamSet::requireTyped(const std::string& key, ParamType type,
                                              const char* getter) const {
    const int index = findIndex(key);
    const std::string call = prefix() + getter + "(" + inQuotes(key) + "): ";
    if (index < 0) throw Error(call + "no such parameter (programming error)");
    if (table()[size_t(index)].type != type) {
        throw Error(call + "parameter is " + paramTypeName(table()[size_t(index)].type) + ", not " +
                    paramTypeName(type) + " (programming error)");
    }
    return m_values[size_t(index)];
}

void ParamSet::set(const std::string& key, const std::string& text) {
    const size_t index = requireKnownKey(key);
    Parsed parsed = parseValue(table()[index], text);
    if (!parsed.value) throw Error(prefix() + "parameter " + inQuotes(key) + " " + parsed.reason);
    m_values[index] = std::move(*parsed.value);
}

void ParamSet::setJson(const std::string& key, const nlohmann::json& value) {
    const size_t index = requireKnownKey(key);
    // Scalars go through the text rules, so JSON and command line accept exactly the same.
    if (value.is_string()) return set(key, value.get<std::string>());
    if (value.is_boolean() || value.is_number()) return set(key, value.dump());
    const ParamSpec& spec = table()[index];
    const std::string expected = spec.type == ParamType::Bool    ? "a boolean"
                                 : spec.type == ParamType::Int   ? "an integer"
                                 : spec.type == ParamType::Float ? "a number"
                                                                 : "a string";
    throw Error(prefix() + "parameter " + inQuotes(key) + " expects " + expected + ", got JSON " +
                value.type_name());
}

void ParamSet::apply(const nlohmann::json& object, const std::string& context) {
    const std::string where = context.empty() ? "" : context + ": ";
    if (!object.is_object()) {
        throw Error(where + prefix() + "parameters must be a JSON object, got " +
                    object.type_name());
    }
    ParamSet updated = *this;  // all or nothing
    for (const auto& [key, value] : object.items()) {
        try {
            updated.setJson(key, value);
        } catch (const Error& e) {
            throw Error(where + e.what());
        }
    }
    *this = std::move(updated);
}

bool ParamSet::getBool(const std::string& key) const {
    return std::get<bool>(requireTyped(key, ParamType::Bool, "getBool"));
}
int ParamSet::getInt(const std::string& key) const {
    return std::get<int>(requireTyped(key, ParamType::Int, "getInt"));
}
float ParamSet::getFloat(const std::string& key) const {
    return float(std::get<double>(requireTyped(key, ParamType::Float, "getFloat")));
}
std::string ParamSet::getEnum(const std::string& key) const {
    return std::get<std::string>(requireTyped(key, ParamType::Enum, "getEnum"));
}

std::string ParamSet::getText(const std::string& key) const {
    const int index = findIndex(key);
    if (index < 0) throw Error(prefix() + "getText(" + inQuotes(key) + "): no such parameter");
    return canonicalText(m_values[size_t(index)]);
}

const ParamSpec& ParamSet::spec(const std::string& key) const {
    return table()[requireKnownKey(key)];
}

nlohmann::json ParamSet::toJson() const {
    return nlohmann::json(toOrderedJson());
}

nlohmann::ordered_json ParamSet::toOrderedJson() const {
    nlohmann::ordered_json out = nlohmann::ordered_json::object();
    for (size_t i = 0; i < table().size(); ++i) {
        std::visit([&](const auto& v) { out[table()[i].name] = v; }, m_values[i]);
    }
    return out;
}

std::string ParamSet::toString() const {
    std::string out;
    for (size_t i = 0; i < table().size(); ++i) {
        if (i > 0) out += ' ';
        out += table()[i].name + "=" + canonicalText(m_values[i]);
    }
    return out;
}

std::vector<std::string> ParamSet::changedKeys(const ParamSet& other) const {
    std::vector<std::string> keys;
    for (size_t i = 0; i < table().size(); ++i) {
        const int j = other.findIndex(table()[i].name);
        if (j < 0 || other.m_values[size_t(j)] != m_values[i]) keys.push_back(table()[i].name);
    }
    for (const ParamSpec& spec : other.table()) {
        if (findIndex(spec.name) < 0) keys.push_back(spec.name);
    }
    return keys;
}

bool ParamSet::changesNeedRebuild(const std::vector<std::string>& keys) const {
    for (const std::string& key : keys) {
        const int index = findIndex(key);
        if (index < 0 || table()[size_t(index)].stage == ParamStage::Rebuild) return true;
    }
    return false;
}

}  // namespace gilab
