#pragma once
/**
 * The version a technique module is built against. A module (gilab-technique-<id>.so) exports
 * `extern "C" const char* gilab_module_abi()`, compiled from these headers
 * (cmake/gilab_module_abi.cpp); gilab refuses a module whose string differs from its own, since
 * the Technique interface is C++ with no stable binary interface between versions.
 */
#include <string>

#include "core/util/build_info.h"

namespace gilab {

inline constexpr const char* kModuleAbiSymbol = "gilab_module_abi";

/** "gilab <version> (<git commit>)" of the headers this is compiled from. */
inline std::string moduleAbi() {
    return std::string("gilab ") + build::kVersion + " (" + build::kGitCommit + ")";
}

}  // namespace gilab
