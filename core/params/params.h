#pragma once
/**
 * Typed technique parameters. One table of ParamSpec per technique drives help text, config
 * validation, sweeps, report columns and toString; ParamSet holds the current values.
 *
 * Text parsing is strict and shared by defaults, command-line and config input:
 *   Bool  true/false/1/0/on/off (any case), canonical text "true"/"false";
 *   Int   optional sign and decimal digits only ("1.5", "1e3", "0x10" are rejected);
 *   Float a finite decimal number (std::from_chars rules plus an optional '+'); NaN, Inf,
 *         values beyond float range and trailing characters are rejected. Stored as double,
 *         canonical text is the shortest round-trip form ("0.1", "1e-05");
 *   Enum  exactly one of the choices (case-sensitive).
 * Surrounding whitespace is ignored. Every error is a gilab::Error naming the owner and key.
 */
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include <nlohmann/json.hpp>

namespace gilab {

enum class ParamType { Bool, Int, Float, Enum };
enum class ParamStage { Rebuild, PerFrame };  // Rebuild = needs setup() again; PerFrame = uniform

struct ParamSpec {
    std::string name;  // snake_case, e.g. "cone_count"
    ParamType type = ParamType::Float;
    std::string defaultValue;  // textual, parsed by the same rules as user input
    double minValue = -std::numeric_limits<double>::infinity();  // inclusive, Int/Float only
    double maxValue = std::numeric_limits<double>::infinity();
    std::vector<std::string> choices;  // Enum only
    std::string unit;                  // e.g. "px", "deg", ""
    std::string help;                  // one line
    ParamStage stage = ParamStage::PerFrame;
    // Further rules on the value, checked by set() and shown by `gilab list`
    bool powerOfTwo = false;          // Int only: 1, 2, 4, ... within the range
    bool odd = false;                 // Int only: 1, 3, 5, ... within the range
    std::vector<double> alsoAllowed;  // Int/Float: accepted outside the range (e.g. 0 = auto)
    /** A rule involving other parameters, in words ("a multiple of clusters"): shown by
     *  `gilab list`, checked by the technique's TechniqueInfo::checkParams. */
    std::string crossRule;
};

// Helpers to write spec tables tersely.
ParamSpec boolParam(std::string name, bool def, std::string help,
                    ParamStage stage = ParamStage::PerFrame);
ParamSpec intParam(std::string name, int def, double minValue, double maxValue, std::string unit,
                   std::string help, ParamStage stage = ParamStage::PerFrame);
ParamSpec floatParam(std::string name, double def, double minValue, double maxValue,
                     std::string unit, std::string help, ParamStage stage = ParamStage::PerFrame);
ParamSpec enumParam(std::string name, std::string def, std::vector<std::string> choices,
                    std::string help, ParamStage stage = ParamStage::PerFrame);

// Rules added to a spec: `requirePowerOfTwo(intParam(...))`, `allowValue(0, floatParam(...))`.
ParamSpec requirePowerOfTwo(ParamSpec spec);
ParamSpec requireOdd(ParamSpec spec);
ParamSpec allowValue(double value, ParamSpec spec);
ParamSpec addCrossRule(std::string rule, ParamSpec spec);

/** "bool", "int", "float", "enum"; "rebuild", "per-frame". */
const char* paramTypeName(ParamType type);
const char* paramStageName(ParamStage stage);

class ParamSet {
public:
    ParamSet() = default;
    /** Fills defaults; throws gilab::Error if a spec is inconsistent (bad default, range,
     *  duplicate or non-snake_case name, enum default not a choice). owner = technique id. */
    ParamSet(std::vector<ParamSpec> specs, std::string owner);

    /** Parses and validates `text` for `key` (rules at the top of this file). */
    void set(const std::string& key, const std::string& text);
    /** Same from JSON: bools, numbers (integers only for Int) and strings (parsed as text). */
    void setJson(const std::string& key, const nlohmann::json& value);
    /** Sets every key of a JSON object, all or nothing; messages start with `context`. */
    void apply(const nlohmann::json& object, const std::string& context);

    // Typed access; a missing key or another type is a programming error and throws.
    bool getBool(const std::string& key) const;
    int getInt(const std::string& key) const;
    float getFloat(const std::string& key) const;
    std::string getEnum(const std::string& key) const;
    /** Canonical text of the value (parses back to the same value). */
    std::string getText(const std::string& key) const;

    bool has(const std::string& key) const { return findIndex(key) >= 0; }
    const std::string& owner() const { return m_owner; }
    const std::vector<ParamSpec>& specs() const { return table(); }
    const ParamSpec& spec(const std::string& key) const;

    /** {key: typed value}. nlohmann::json sorts keys; toOrderedJson keeps spec order. */
    nlohmann::json toJson() const;
    nlohmann::ordered_json toOrderedJson() const;
    /** "a=1 b=0.5 c=dense" in spec order. */
    std::string toString() const;
    /** Keys whose values differ, in this set's spec order, then keys only `other` has. */
    std::vector<std::string> changedKeys(const ParamSet& other) const;
    /** True if any key is a Rebuild parameter; an unknown key counts as Rebuild. */
    bool changesNeedRebuild(const std::vector<std::string>& keys) const;

private:
    using Value = std::variant<bool, int, double, std::string>;

    int findIndex(const std::string& key) const;
    size_t requireKnownKey(const std::string& key) const;  // user-facing unknown-key message
    const Value& requireTyped(const std::string& key, ParamType type, const char* getter) const;
    std::string prefix() const;

    /** The specs (a default-constructed or moved-from set has none). */
    const std::vector<ParamSpec>& table() const {
        static const std::vector<ParamSpec> kNone;
        return m_specs ? *m_specs : kNone;
    }

    // Immutable and shared by every copy: an experiment plans 100k runs, each with a copy.
    std::shared_ptr<const std::vector<ParamSpec>> m_specs;
    std::vector<Value> m_values;  // parallel to m_specs
    std::string m_owner;
};

/** Allowed values in words: "[1, 64]", ">= 0", "<= 5", "any" (Int/Float), "a|b|c" (Enum),
 *  "true|false" (Bool); with the spec's rules: "power of two in [32, 512]", "0 or [8, 4096]",
 *  "0 or odd in [1, 9]", "-1 or 1", then "; <crossRule>" when it has one. */
std::string describeParamRange(const ParamSpec& spec);
/** The same as a phrase for messages ("must be ..."): "in [1, 64]", "a power of two in [32, 512]",
 *  "0 or in [8, 4096]", ">= 0"; without the cross rule. */
std::string describeAllowedValues(const ParamSpec& spec);
/** Aligned table, one row per spec: name, type, default, range/choices, unit, help, stage. */
std::string formatParamHelp(const std::vector<ParamSpec>& specs);
/** "key=value" -> {key, value}, both trimmed; throws gilab::Error if malformed. */
std::pair<std::string, std::string> splitAssignment(const std::string& text);

}  // namespace gilab
