#pragma once
/**
 * Self-registration of techniques. Each technique's .cpp ends with one line:
 *     GILAB_REGISTER_TECHNIQUE(MyTechnique)
 * where MyTechnique has `static TechniqueInfo describe();` and a default constructor.
 * Techniques are built as CMake OBJECT libraries, so the registration object is always linked.
 */
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "core/technique/technique.h"

namespace gilab {

class TechniqueRegistry {
public:
    using Factory = std::function<std::unique_ptr<Technique>()>;

    static TechniqueRegistry& instance();

    /** Registers a technique; a second id of the same name is a build error reported at start. */
    void add(TechniqueInfo info, Factory factory);
    /** Sorted by id. */
    std::vector<const TechniqueInfo*> list() const;
    const TechniqueInfo* find(const std::string& id) const;
    /** Throws gilab::Error naming the id and listing the registered ones when unknown. */
    const TechniqueInfo& get(const std::string& id) const;
    std::unique_ptr<Technique> create(const std::string& id) const;
    /** Default parameters of a technique, validated against its spec table. */
    ParamSet defaultParams(const std::string& id) const;
    /** Where a technique comes from: "built in", or the path of the module that registered it
     *  (core/technique/modules.h). */
    std::string origin(const std::string& id) const;

    /** The origin given to registrations from now on (empty: built in); set around dlopen. */
    void setOrigin(std::string origin) { m_origin = std::move(origin); }
    /** Forgets every technique registered from `origin` (a module that was refused). */
    void removeOrigin(const std::string& origin);

private:
    struct Entry {
        TechniqueInfo info;
        Factory factory;
        std::string origin;
    };
    std::vector<Entry> m_entries;
    std::vector<std::string> m_duplicates;
    std::string m_origin;
};

struct TechniqueRegistrar {
    TechniqueRegistrar(TechniqueInfo info, TechniqueRegistry::Factory factory) {
        TechniqueRegistry::instance().add(std::move(info), std::move(factory));
    }
};

}  // namespace gilab

#define GILAB_REGISTER_TECHNIQUE(Class)                                                      \
    namespace {                                                                              \
    const ::gilab::TechniqueRegistrar kGilabRegistrar_##Class{                               \
        Class::describe(), [] { return std::unique_ptr<::gilab::Technique>(new Class()); }}; \
    }
