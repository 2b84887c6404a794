#include "core/util/json_reader.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <vector>

#include "core/util/error.h"

namespace gilab {

namespace {

std::string formatNumber(double v) {
    std::ostringstream s;
    s << v;
    return s.str();
}

/** A char iterator that records how far the parser has read (for line and column). */
class CountingIterator {
public:
    using iterator_category = std::forward_iterator_tag;
    using value_type = char;
    using difference_type = std::ptrdiff_t;
    using pointer = const char*;
    using reference = const char&;

    CountingIterator() = default;
    CountingIterator(const char* p, const char* begin, size_t* consumed)
        : m_p(p), m_begin(begin), m_consumed(consumed) {}
    reference operator*() const { return *m_p; }
    CountingIterator& operator++() {
        ++m_p;
        *m_consumed = size_t(m_p - m_begin);
        return *this;
    }
    CountingIterator operator++(int) {
        CountingIterator old = *this;
        ++*this;
        return old;
    }
    bool operator==(const CountingIterator& other) const { return m_p == other.m_p; }
    bool operator!=(const CountingIterator& other) const { return m_p != other.m_p; }

private:
    const char* m_p = nullptr;
    const char* m_begin = nullptr;
    size_t* m_consumed = nullptr;
};

/**
 * Builds the document like nlohmann's own DOM parser, but refuses duplicate keys and remembers
 * the key path of the value being read, so every error can name it.
 */
class StrictDomBuilder {
public:
    using json = nlohmann::json;

    explicit StrictDomBuilder(json& root) : m_root(root) {}

    bool null() { return place(nullptr) != nullptr; }
    bool boolean(bool v) { return place(v) != nullptr; }
    bool number_integer(json::number_integer_t v) { return place(v) != nullptr; }
    bool number_unsigned(json::number_unsigned_t v) { return place(v) != nullptr; }
    bool number_float(json::number_float_t v, const json::string_t&) { return place(v) != nullptr; }
    bool string(json::string_t& v) { return place(std::move(v)) != nullptr; }
    bool binary(json::binary_t& v) { return place(json::binary(std::move(v))) != nullptr; }

    bool start_object(size_t) { return open(json::object()); }
    bool start_array(size_t) { return open(json::array()); }
    bool end_object() { return close(); }
    bool end_array() { return close(); }

    bool key(json::string_t& k) {
        Frame& f = m_stack.back();
        if (f.value->contains(k)) {
            duplicate = true;
            duplicatePath = join(containerPath(), k);
            return false;
        }
        f.key = std::move(k);
        return true;
    }

    bool parse_error(size_t position, const std::string& token, const json::exception& e) {
        errorPosition = position;
        errorToken = token;
        errorId = e.id;
        errorMessage = e.what();
        errorPath = currentPath();
        return false;
    }

    /** The key path of the value about to be read ("" at the document root). Built from the
     *  frames' own segments on demand (errors only), so memory stays linear in the depth. */
    std::string currentPath() const {
        if (m_stack.empty()) return "";
        return join(containerPath(), segmentOfNext(m_stack.back()));
    }

    bool duplicate = false;
    std::string duplicatePath;
    size_t errorPosition = 0;
    std::string errorToken, errorMessage, errorPath;
    int errorId = 0;
    bool tooDeep = false;

    /** Containers nest at most this deep: far beyond any scene or experiment (they use < 10), and
     *  short of what recursive readers of the document could take. */
    static constexpr size_t kMaxDepth = 256;

private:
    struct Frame {
        json* value;
        std::string segment;  // how its parent names it: "key" or "[i]" ("" at the root)
        std::string key;      // objects: the key of the value being read
    };

    /** "key" of the next value of an object, "[i]" of an array. */
    static std::string segmentOfNext(const Frame& f) {
        return f.value->is_array() ? "[" + std::to_string(f.value->size()) + "]" : f.key;
    }

    static std::string join(const std::string& path, const std::string& segment) {
        if (path.empty() || segment.empty() || segment[0] == '[') return path + segment;
        return path + "." + segment;
    }

    /** The path of the innermost open container. */
    std::string containerPath() const {
        std::string path;
        for (const Frame& f : m_stack)
            path = join(path, f.segment);
        return path;
    }

    json* place(json&& v) {
        if (m_stack.empty()) {
            m_root = std::move(v);
            return &m_root;
        }
        Frame& f = m_stack.back();
        if (f.value->is_array()) {
            f.value->push_back(std::move(v));
            return &f.value->back();
        }
        json& slot = (*f.value)[f.key];
        slot = std::move(v);
        return &slot;
    }

    bool open(json&& container) {
        if (m_stack.size() >= kMaxDepth) {
            tooDeep = true;
            return false;
        }
        std::string segment = m_stack.empty() ? std::string() : segmentOfNext(m_stack.back());
        json* value = place(std::move(container));
        m_stack.push_back({value, std::move(segment), {}});
        return true;
    }

    bool close() {
        m_stack.pop_back();
        return true;
    }

    json& m_root;
    std::vector<Frame> m_stack;
};

/** "file:line:column" of the byte at `offset` (both 1-based). */
std::string location(const std::string& text, const std::string& context, size_t offset) {
    offset = std::min(offset, text.size());
    size_t line = 1, lineStart = 0;
    for (size_t i = 0; i < offset; ++i)
        if (text[i] == '\n') {
            ++line;
            lineStart = i + 1;
        }
    return context + ":" + std::to_string(line) + ":" + std::to_string(offset - lineStart + 1);
}

/** nlohmann's message without its "[json.exception...] parse error at line L, column C: ". */
std::string plainParseMessage(const std::string& what) {
    std::string m = what;
    if (m.rfind("[json.exception.", 0) == 0) {
        const size_t close = m.find("] ");
        if (close != std::string::npos) m = m.substr(close + 2);
    }
    if (m.rfind("parse error", 0) == 0) {
        const size_t colon = m.find(": ");
        if (colon != std::string::npos) m = m.substr(colon + 2);
    }
    return m;
}

}  // namespace

nlohmann::json parseJsonText(const std::string& text, const std::string& context) {
    nlohmann::json root;
    StrictDomBuilder builder(root);
    size_t consumed = 0;
    const char* begin = text.data();
    const CountingIterator first(begin, begin, &consumed);
    const CountingIterator last(begin + text.size(), begin, &consumed);
    bool ok = false;
    try {
        ok = nlohmann::json::sax_parse(first, last, &builder);
    } catch (const nlohmann::json::exception& e) {  // not expected: the builder takes errors
        throw Error(context + ": malformed JSON: " + plainParseMessage(e.what()));
    }
    if (ok) return root;
    const auto withPath = [](const std::string& path) {
        return path.empty() ? std::string() : "\"" + path + "\": ";
    };
    if (builder.duplicate) {
        // `consumed` is just past the key's closing quote; point at its opening quote
        size_t at = consumed >= 2 ? consumed - 2 : 0;
        while (at > 0 && !(text[at] == '"' && text[at - 1] != '\\'))
            --at;
        throw Error(location(text, context, at) + ": duplicate key \"" + builder.duplicatePath +
                    "\" (each key may appear once per object; JSON parsers disagree on which " +
                    "copy wins)");
    }
    if (builder.tooDeep) {
        const size_t at = consumed > 0 ? consumed - 1 : 0;
        throw Error(location(text, context, at) + ": arrays and objects nested more than " +
                    std::to_string(StrictDomBuilder::kMaxDepth) +
                    " levels deep (a scene or an experiment needs fewer than 10)");
    }
    if (builder.errorId == 406) {  // a number beyond the range of a double
        const size_t start = builder.errorPosition >= builder.errorToken.size()
                                 ? builder.errorPosition - builder.errorToken.size()
                                 : 0;
        std::string token = builder.errorToken;
        if (token.size() > 40) token = token.substr(0, 37) + "...";
        throw Error(location(text, context, start) + ": " + withPath(builder.errorPath) +
                    "number out of range (" + token +
                    " does not fit a double, whose largest value is about 1.8e308)");
    }
    if (text.find_first_not_of(" \t\r\n") == std::string::npos)
        throw Error(context + ": empty file (expected a JSON document)");
    if (!builder.errorMessage.empty()) {
        // The path is left out: after a syntax error it is often the previous key's
        const size_t at = builder.errorPosition > 0 ? builder.errorPosition - 1 : 0;
        throw Error(location(text, context, at) +
                    ": malformed JSON: " + plainParseMessage(builder.errorMessage));
    }
    throw Error(context + ": malformed JSON");
}

nlohmann::json readJsonFile(const std::string& path, const std::string& what) {
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec))
        throw Error(path + ": is a folder, expected a file (" + what + ")");
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error(path + ": cannot open " + what);
    std::stringstream text;
    text << in.rdbuf();
    if (in.bad()) throw Error(path + ": cannot read " + what);
    return parseJsonText(text.str(), path);
}

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
