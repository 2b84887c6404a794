#pragma once
/**
 * Technique modules: techniques built out of the tree against an installed gilab
 * (find_package(gilab), gilab_add_technique) as gilab-technique-<id>.so, loaded at start.
 * Searched, in order (docs/architecture.md, "Technique modules"):
 *   1. every --technique-dir given on the command line (a folder or a .so file);
 *   2. every entry of GILAB_TECHNIQUE_PATH (':'-separated folders or .so files);
 *   3. the folder <binary dir>/../<libdir>/gilab/techniques beside an installed gilab (libdir:
 *      lib, or lib/<multiarch> for a /usr prefix on Debian; where gilab_add_technique installs).
 * A module built against another gilab version (core/technique/module_abi.h) is refused with an
 * error naming the file and both versions; so is a file that is not a gilab module.
 */
#include <filesystem>
#include <string>
#include <vector>

namespace gilab {

struct ModuleSearch {
    std::vector<std::filesystem::path> explicitPaths;  // --technique-dir, then the variable
    std::filesystem::path besideBinary;                // <binary dir>/../<libdir>/gilab/techniques
};

/** The search of this process: `dirs` (the command line), GILAB_TECHNIQUE_PATH, the folder
 *  beside `executable` (/proc/self/exe when empty). */
ModuleSearch moduleSearch(const std::vector<std::string>& dirs,
                          std::filesystem::path executable = {});

/** The module files the search finds, in load order (a folder's files sorted by name). Throws
 *  gilab::Error when an explicit path does not exist. */
std::vector<std::filesystem::path> findModules(const ModuleSearch& search);

/** Loads one module: its techniques register with TechniqueRegistry under its path as origin.
 *  Throws gilab::Error naming the file when it cannot be loaded, has no gilab_module_abi, or was
 *  built against another gilab version. Loading the same file twice is a no-op. */
void loadTechniqueModule(const std::filesystem::path& file);

/** findModules + loadTechniqueModule for each; returns the files loaded. */
std::vector<std::filesystem::path> loadTechniqueModules(const ModuleSearch& search);

}  // namespace gilab
