#include "core/util/json_reader.h"

#include <cmath>
#include <sstream>

#include "core/util/error.h"

namespace gilab {

namespace {

std::string formatNumber(double v) {
    std::ostringstream s;
    s << v;
    return s.str();
}

}  // namespace

JsonNode::JsonNode(const nlohmann::json& value, std::string context, std::string path)
    : m_value(&value), m_context(std::move(context)), m_path(std::move(path)) {}

void JsonNode::fail(const std::string& message) const {
    const std::string where = m_path.empty() ? "(document root)" : "\"" + m_path + "\"";
    throw Error(m_context + ": " + where + ": " + message);
}

std::string JsonNode::childPath(const std::string& key) const {
    return m_path.empty() ? key : m_path + "." + key;
}

void JsonNode::expectKeys(std::initializer_list<const char*> allowed) const {
    if (!m_value->is_object()) {
        fail(std::string("expected an object, got ") + m_value->type_name());
    }
    for (const auto& item : m_value->items()) {
        bool known = false;
        for (const char* key : allowed)
            known = known || item.key() == key;
        if (!known) {
            std::string list;
            for (const char* key : allowed)
                list += (list.empty() ? "" : ", ") + std::string(key);
            throw Error(m_context + ": unknown key \"" + childPath(item.key()) +
                        "\" (allowed here: " + list + ")");
        }
    }
}

bool JsonNode::has(const char* key) const {
    return m_value->is_object() && m_value->contains(key);
}

JsonNode JsonNode::operator[](const char* key) const {
    if (!m_value->is_object()) {
        fail(std::string("expected an object, got ") + m_value->type_name());
    }
    if (!has(key)) fail(std::string("missing required key \"") + key + "\"");
    return JsonNode(m_value->at(key), m_context, childPath(key));
}

JsonNode JsonNode::item(size_t index) const {
    if (index >= arraySize()) fail("expected at least " + std::to_string(index + 1) + " items");
    return JsonNode(m_value->at(index), m_context, m_path + "[" + std::to_string(index) + "]");
}

size_t JsonNode::arraySize() const {
    if (!m_value->is_array()) fail(std::string("expected an array, got ") + m_value->type_name());
    return m_value->size();
}

double JsonNode::number() const {
    if (!m_value->is_number()) fail(std::string("expected a number, got ") + m_value->type_name());
    const double v = m_value->get<double>();
    if (!std::isfinite(v)) fail("number is not finite");
    return v;
}

double JsonNode::numberIn(double lo, double hi) const {
    const double v = number();
    if (v < lo || v > hi) {
        fail("out of range: must be in [" + formatNumber(lo) + ", " + formatNumber(hi) + "] (got " +
             formatNumber(v) + ")");
    }
    return v;
}

int JsonNode::integerIn(int lo, int hi) const {
    const double v = number();
    if (v != std::floor(v)) fail("expected an integer (got " + formatNumber(v) + ")");
    if (v < lo || v > hi) {
        fail("out of range: must be in [" + std::to_string(lo) + ", " + std::to_string(hi) +
             "] (got " + formatNumber(v) + ")");
    }
    return int(v);
}

bool JsonNode::boolean() const {
    if (!m_value->is_boolean()) {
        fail(std::string("expected true or false, got ") + m_value->type_name());
    }
    return m_value->get<bool>();
}

std::string JsonNode::string() const {
    if (!m_value->is_string()) fail(std::string("expected a string, got ") + m_value->type_name());
    return m_value->get<std::string>();
}

glm::vec3 JsonNode::vec3() const {
    if (arraySize() != 3) fail("expected an array of 3 numbers");
    return {float(item(0).number()), float(item(1).number()), float(item(2).number())};
}

glm::vec4 JsonNode::vec4() const {
    if (arraySize() != 4) fail("expected an array of 4 numbers");
    return {float(item(0).number()), float(item(1).number()), float(item(2).number()),
            float(item(3).number())};
}

glm::vec3 JsonNode::color(double maxValue) const {
    if (arraySize() != 3) fail("expected an RGB array of 3 numbers");
    glm::vec3 c;
    for (int i = 0; i < 3; ++i)
        c[i] = float(item(size_t(i)).numberIn(0.0, maxValue));
    return c;
}

double numberOr(const JsonNode& obj, const char* key, double fallback) {
    return obj.has(key) ? obj[key].number() : fallback;
}

bool booleanOr(const JsonNode& obj, const char* key, bool fallback) {
    return obj.has(key) ? obj[key].boolean() : fallback;
}

}  // namespace gilab
