#include "core/technique/modules.h"

#include <dlfcn.h>

#include <algorithm>
#include <cstdlib>
#include <set>

#include "core/technique/module_abi.h"
#include "core/technique/registry.h"
#include "core/util/error.h"

namespace gilab {
namespace fs = std::filesystem;
namespace {

constexpr const char* kPathVariable = "GILAB_TECHNIQUE_PATH";

bool isModuleFile(const fs::path& p) {
    const std::string name = p.filename().string();
    return name.starts_with("gilab-technique-") && p.extension() == ".so";
}

void addEntry(const fs::path& entry, const std::string& source, std::vector<fs::path>& out) {
    std::error_code ec;
    if (fs::is_directory(entry, ec)) {
        std::vector<fs::path> found;
        for (const fs::directory_entry& e : fs::directory_iterator(entry, ec))
            if (e.is_regular_file() && isModuleFile(e.path())) found.push_back(e.path());
        std::sort(found.begin(), found.end());
        out.insert(out.end(), found.begin(), found.end());
        return;
    }
    if (fs::is_regular_file(entry, ec)) {
        out.push_back(entry);
        return;
    }
    throw Error(entry.string() + " (from " + source +
                "): no such technique module or folder of modules (gilab-technique-<id>.so)");
}

std::set<fs::path>& loadedFiles() {
    static std::set<fs::path> loaded;
    return loaded;
}

}  // namespace

ModuleSearch moduleSearch(const std::vector<std::string>& dirs, fs::path executable) {
    ModuleSearch search;
    for (const std::string& d : dirs)
        search.explicitPaths.emplace_back(d);
    if (const char* value = std::getenv(kPathVariable)) {
        std::string text = value;
        size_t start = 0;
        while (start <= text.size()) {
            const size_t end = std::min(text.find(':', start), text.size());
            if (end > start) search.explicitPaths.emplace_back(text.substr(start, end - start));
            start = end + 1;
        }
    }
    std::error_code ec;
    if (executable.empty()) executable = fs::read_symlink("/proc/self/exe", ec);
    if (!executable.empty())
        search.besideBinary = executable.parent_path().parent_path() / GILAB_MODULE_DIR_FROM_PREFIX;
    return search;
}

std::vector<fs::path> findModules(const ModuleSearch& search) {
    std::vector<fs::path> out;
    for (const fs::path& p : search.explicitPaths)
        addEntry(p, std::string("--technique-dir or ") + kPathVariable, out);
    std::error_code ec;
    if (!search.besideBinary.empty() && fs::is_directory(search.besideBinary, ec))
        addEntry(search.besideBinary, "the folder beside the gilab binary", out);
    return out;
}

void loadTechniqueModule(const fs::path& file) {
    std::error_code ec;
    const fs::path canonical = fs::weakly_canonical(file, ec);
    const fs::path key = ec ? file : canonical;
    if (loadedFiles().count(key)) return;
    // Its techniques' registrations run inside dlopen; they are tagged with the file's path.
    TechniqueRegistry& registry = TechniqueRegistry::instance();
    registry.setOrigin(key.string());
    void* handle = ::dlopen(key.c_str(), RTLD_NOW | RTLD_LOCAL);
    registry.setOrigin({});
    if (!handle) {
        const char* why = ::dlerror();
        throw Error(key.string() + ": cannot load technique module: " + (why ? why : "unknown"));
    }
    using AbiFunction = const char* (*)();
    auto abi = reinterpret_cast<AbiFunction>(::dlsym(handle, kModuleAbiSymbol));
    if (!abi) {
        registry.removeOrigin(key.string());
        throw Error(key.string() + ": not a gilab technique module (no " + kModuleAbiSymbol +
                    "; build it with gilab_add_technique from find_package(gilab))");
    }
    const std::string built = abi() ? abi() : "";
    const std::string mine = moduleAbi();
    if (built != mine) {
        registry.removeOrigin(key.string());
        throw Error(key.string() + ": technique module built against " + built + ", but this is " +
                    mine + "; rebuild the module against this gilab");
    }
    loadedFiles().insert(key);  // kept loaded for the life of the process
}

std::vector<fs::path> loadTechniqueModules(const ModuleSearch& search) {
    std::vector<fs::path> files = findModules(search);
    for (const fs::path& f : files)
        loadTechniqueModule(f);
    return files;
}

}  // namespace gilab
