#pragma once
/**
 * Strict, typed access to a parsed JSON document (scene descriptions, experiment configs).
 *
 * Every value carries the file it came from and its key path ("lights[0].color"), so each
 * error names both: `scenes/x.json: "lights[0].intensity": must be >= 0 (got -1)`. Objects list
 * the keys they accept (`expectKeys`); anything else is an `unknown key` error.
 *
 * Files are read with `readJsonFile` / `parseJsonText`, which are stricter than nlohmann's
 * parser: a duplicate key, a number beyond the range of a double (`1e999`) and malformed text
 * are all gilab::Error naming the file, the line and column, and the key path.
 */
#include <cstddef>
#include <initializer_list>
#include <string>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

namespace gilab {

class JsonNode {
public:
    /** `context` prefixes every message, e.g. the file name or `x.json (variant "spot")`. */
    JsonNode(const nlohmann::json& value, std::string context, std::string path = "");

    const nlohmann::json& raw() const { return *m_value; }
    const std::string& path() const { return m_path; }
    const std::string& context() const { return m_context; }

    /** Throws gilab::Error: `<context>: "<path>": <message>`. */
    [[noreturn]] void fail(const std::string& message) const;

    // Structure
    bool isNull() const { return m_value->is_null(); }
    /** Requires an object whose keys are all in `allowed`; otherwise `unknown key "<path>"`. */
    void expectKeys(std::initializer_list<const char*> allowed) const;
    bool has(const char* key) const;
    JsonNode operator[](const char* key) const;  // the key must exist (check has() first)
    JsonNode item(size_t index) const;           // requires an array with more than `index` items
    size_t arraySize() const;                    // requires an array

    // Scalars (all check the type; numbers must be finite)
    double number() const;
    double numberIn(double lo, double hi) const;  // closed range [lo, hi]
    int integerIn(int lo, int hi) const;
    bool boolean() const;
    std::string string() const;

    // Fixed-size numeric arrays
    glm::vec3 vec3() const;
    glm::vec4 vec4() const;
    /** An RGB colour: 3 finite numbers, each >= 0 (and <= maxValue). */
    glm::vec3 color(double maxValue = 1e30) const;

private:
    std::string childPath(const std::string& key) const;

    const nlohmann::json* m_value;
    std::string m_context;
    std::string m_path;
};

/**
 * Parses JSON text. Errors (gilab::Error) start with `context` (the file name) and name the line
 * and column and, where known, the key path: `x.json:3:17: "lights[0].intensity": number out of
 * range (1e999 does not fit a double)`, `x.json:5:3: duplicate key "camera.position"`.
 */
nlohmann::json parseJsonText(const std::string& text, const std::string& context);

/** Reads and parses a JSON file; `what` names it in messages ("scene file", "experiment
 *  config"): `x.json: cannot open scene file`. */
nlohmann::json readJsonFile(const std::string& path, const std::string& what);

/** Optional-key helpers: return `fallback` when the key is absent. */
double numberOr(const JsonNode& obj, const char* key, double fallback);
bool booleanOr(const JsonNode& obj, const char* key, bool fallback);

}  // namespace gilab
