#pragma once
/** The gilab command line: `gilab --help` lists the commands. */
#include <string>
#include <vector>

namespace gilab::cli {

/** Exit codes, stable for scripts. */
enum ExitCode : int {
    kExitOk = 0,
    kExitError = 1,        // bad input, I/O or Vulkan failure (message on stderr)
    kExitUsage = 2,        // bad command line
    kExitUnsupported = 3,  // the technique cannot run on this scene (reason printed and saved)
    kExitNonFinite = 4,    // the run finished but an output has NaN/Inf pixels (counted, saved)
};

int runMain(int argc, char** argv);

/** Options of `gilab render`, also used by tests. */
struct RenderOptions {
    std::string scenePath;  // "" = the built-in Cornell box; "file.json#variant" selects a variant
    std::string technique = "direct";
    std::vector<std::string> assignments;  // "key=value" or "shared.key=value"
    std::string outDir = "results/render";
    std::string resolution;  // "WxH", "" = the scene's
    int warmupFrames = 1;
    int frames = 3;
    std::string device;
    bool validation = false;
    bool quiet = false;
    std::string commandLine;
};
int runRender(const RenderOptions& options);

int runList(bool json);
int runDevices(const std::string& device);
int runSceneInfo(const std::string& scenePath, bool json);

}  // namespace gilab::cli
