#include "core/util/embedded_text.h"

#include <algorithm>
#include <map>
#include <mutex>

namespace gilab {
namespace {

struct Registry {
    std::mutex mutex;
    std::map<std::string, std::string> texts;
};

Registry& registry() {
    static Registry r;
    return r;
}

}  // namespace

EmbeddedTextRegistration::EmbeddedTextRegistration(const char* name, const char* text) {
    Registry& r = registry();
    std::lock_guard lock(r.mutex);
    r.texts[name] = text;
}

std::optional<std::string> embeddedText(const std::string& name) {
    Registry& r = registry();
    std::lock_guard lock(r.mutex);
    auto it = r.texts.find(name);
    if (it == r.texts.end()) return std::nullopt;
    return it->second;
}

std::vector<std::string> embeddedTextNames() {
    Registry& r = registry();
    std::lock_guard lock(r.mutex);
    std::vector<std::string> names;
    for (const auto& [name, text] : r.texts)
        names.push_back(name);
    return names;
}

}  // namespace gilab
