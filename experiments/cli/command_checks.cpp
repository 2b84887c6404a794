// Checks and hints the commands share: parameter values before any work, output folders before
// anything is written, the command that runs this gilab, out-of-memory messages.
#include <algorithm>
#include <filesystem>
#include <string>

#include "core/passes/shared_passes.h"
#include "core/technique/frame_harness.h"
#include "core/technique/registry.h"
#include "core/vk/check.h"
#include "experiments/cli/cli.h"

namespace gilab::cli {

namespace fs = std::filesystem;

namespace {
std::string g_invocation;  // argv[0] as runMain saw it ("" = not set: "gilab")
}  // namespace

void checkParamValues(const std::string& techniqueId, const ParamSet& technique,
                      const ParamSet& shared) {
    try {
        (void)sharedSettingsFromParams(shared);  // cross-parameter limits of the shared passes
        const TechniqueInfo* info = TechniqueRegistry::instance().find(techniqueId);
        if (info && info->checkParams) info->checkParams(technique);
    } catch (const UsageError&) {
        throw;
    } catch (const Error& e) {
        throw UsageError(std::string("--set: ") + e.what());
    }
}

void checkOutputFolder(const std::string& option, const fs::path& dir) {
    // The deepest part of the path that exists must be a folder (or a link to one)
    std::error_code ec;
    for (fs::path p = dir; !p.empty(); p = p.parent_path()) {
        const fs::file_status status = fs::status(p, ec);
        if (ec && status.type() != fs::file_type::not_found)
            throw UsageError("cannot write to " + dir.string() + " (" + option +
                             "): cannot check " + p.string() + ": " + ec.message());
        if (!fs::exists(status)) {
            if (p == p.parent_path()) break;  // the root
            continue;
        }
        if (fs::is_directory(status)) return;
        const std::string what = fs::is_regular_file(status) ? "a file" : "not a folder";
        throw UsageError("cannot write to " + dir.string() + " (" + option + "): " + p.string() +
                         " is " + what + (what == "a file" ? ", not a folder" : ""));
    }
}

void setInvocation(const std::string& argv0) {
    g_invocation = argv0;
}

std::string runnableCommandPath(const std::string& argv0, const fs::path& cwd) {
    std::string out;
    if (argv0.empty()) {
        out = "gilab";
    } else if (argv0.find('/') == std::string::npos) {
        out = argv0;  // found on PATH by the shell
    } else {
        const fs::path exe =
            (fs::path(argv0).is_absolute() ? fs::path(argv0) : cwd / argv0).lexically_normal();
        const fs::path rel = exe.lexically_relative(cwd);
        const bool inside = !rel.empty() && *rel.begin() != "..";
        if (!inside) {
            out = exe.string();
        } else {
            out = rel.string();
            if (!rel.has_parent_path()) out = "./" + out;
        }
    }
    return quoteForShell(out);
}

std::string quoteForShell(const std::string& text) {
    if (!text.empty() &&
        text.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789"
                               "_./+-=:,@%") == std::string::npos)
        return text;
    std::string quoted = "'";
    for (char c : text)
        quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return quoted + "'";
}

std::string runnableGilab() {
    std::error_code ec;
    const fs::path cwd = fs::current_path(ec);
    return runnableCommandPath(g_invocation, ec ? fs::path("/") : cwd);
}

std::string describeOutOfMemory(int width, int height, const vk::OutOfMemoryError& e) {
    const std::string size = std::to_string(width) + "x" + std::to_string(height);
    const std::string half =
        std::to_string(std::max(1, width / 2)) + "x" + std::to_string(std::max(1, height / 2));
    return "out of memory at " + size + ": " + e.what() +
           ". The resolution (or a parameter that sizes '" + e.resource() +
           "') is too large for this device's memory: try a smaller --resolution (e.g. " + half +
           ")";
}

}  // namespace gilab::cli
