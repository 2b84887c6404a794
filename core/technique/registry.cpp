#include "core/technique/registry.h"

#include <algorithm>

#include "core/util/error.h"

namespace gilab {

TechniqueRegistry& TechniqueRegistry::instance() {
    static TechniqueRegistry registry;
    return registry;
}

void TechniqueRegistry::add(TechniqueInfo info, Factory factory) {
    if (find(info.id)) {
        m_duplicates.push_back(info.id + " (" + origin(info.id) + " and " +
                               (m_origin.empty() ? std::string("built in") : m_origin) + ")");
        return;
    }
    m_entries.push_back({std::move(info), std::move(factory), m_origin});
}

std::vector<const TechniqueInfo*> TechniqueRegistry::list() const {
    if (!m_duplicates.empty())
        throw Error("technique id registered twice: " + m_duplicates.front() +
                    " (each technique folder or module must have a unique id)");
    std::vector<const TechniqueInfo*> out;
    for (const Entry& e : m_entries)
        out.push_back(&e.info);
    std::sort(out.begin(), out.end(), [](auto* a, auto* b) { return a->id < b->id; });
    return out;
}

const TechniqueInfo* TechniqueRegistry::find(const std::string& id) const {
    for (const Entry& e : m_entries)
        if (e.info.id == id) return &e.info;
    return nullptr;
}

const TechniqueInfo& TechniqueRegistry::get(const std::string& id) const {
    if (const TechniqueInfo* info = find(id)) return *info;
    std::string known;
    for (const TechniqueInfo* info : list())
        known += (known.empty() ? "" : ", ") + info->id;
    throw Error("unknown technique \"" + id + "\" (known: " + known + ")");
}

std::unique_ptr<Technique> TechniqueRegistry::create(const std::string& id) const {
    get(id);  // throws with the list of known ids
    for (const Entry& e : m_entries) {
        if (e.info.id != id) continue;
        std::unique_ptr<Technique> technique = e.factory();
        technique->m_info = e.info;
        return technique;
    }
    return nullptr;
}

std::string TechniqueRegistry::origin(const std::string& id) const {
    for (const Entry& e : m_entries)
        if (e.info.id == id) return e.origin.empty() ? "built in" : e.origin;
    return {};
}

void TechniqueRegistry::removeOrigin(const std::string& origin) {
    std::erase_if(m_entries, [&](const Entry& e) { return e.origin == origin; });
}

ParamSet TechniqueRegistry::defaultParams(const std::string& id) const {
    return ParamSet(get(id).params, id);
}

}  // namespace gilab
