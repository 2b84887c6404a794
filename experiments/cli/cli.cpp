#include "experiments/cli/cli.h"

#include <cstdio>

#include <CLI/CLI.hpp>

#include "core/util/error.h"

namespace gilab::cli {

int runMain(int argc, char** argv) {
    CLI::App app{
        "gilab: real-time global illumination techniques side by side on one Vulkan backend,\n"
        "measured against a path-traced ground truth."};
    app.require_subcommand(1);
    app.set_help_all_flag("--help-all", "Help for every command");

    std::string commandLine;
    for (int i = 0; i < argc; ++i)
        commandLine += (i ? " " : "") + std::string(argv[i]);

    bool listJson = false;
    CLI::App* list = app.add_subcommand("list", "List techniques and their parameters");
    list->add_flag("--json", listJson, "Machine-readable output");

    std::string deviceFilter;
    CLI::App* devices =
        app.add_subcommand("devices", "List Vulkan devices and why each is chosen or rejected");
    devices->add_option("--device", deviceFilter, "Device name substring or index");

    std::string infoScene;
    bool infoJson = false;
    CLI::App* info = app.add_subcommand("scene-info", "Load a scene and print what it contains");
    info->add_option("--scene", infoScene, "Scene description (.json[#variant]); default built-in");
    info->add_flag("--json", infoJson, "Machine-readable output");

    RenderOptions render;
    render.commandLine = commandLine;
    CLI::App* rend = app.add_subcommand(
        "render", "Render one technique on one scene: EXR layers, PNG preview, JSON sidecar");
    rend->add_option(
        "--scene", render.scenePath,
        "Scene description (.json, optionally #variant); default: built-in Cornell box");
    rend->add_option("--technique,-t", render.technique, "Technique id (see `gilab list`)")
        ->capture_default_str();
    rend->add_option("--set", render.assignments,
                     "Parameter key=value (technique) or shared.key=value (shared passes); "
                     "repeatable");
    rend->add_option("--out,-o", render.outDir, "Output folder")->capture_default_str();
    rend->add_option("--resolution", render.resolution, "Override the scene resolution, WxH");
    rend->add_option("--warmup", render.warmupFrames, "Warm-up frames (not timed)")
        ->check(CLI::Range(0, 1000))
        ->capture_default_str();
    rend->add_option("--frames", render.frames, "Timed frames")
        ->check(CLI::Range(1, 100000))
        ->capture_default_str();
    rend->add_option("--device", render.device, "Vulkan device name substring or index");
    rend->add_flag("--validation", render.validation, "Enable Vulkan validation layers");
    rend->add_flag("--quiet,-q", render.quiet, "No progress lines");

    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        return app.exit(e) == 0 ? kExitOk : kExitUsage;
    }

    try {
        if (*list) return runList(listJson);
        if (*devices) return runDevices(deviceFilter);
        if (*info) return runSceneInfo(infoScene, infoJson);
        if (*rend) return runRender(render);
    } catch (const Error& e) {
        std::fprintf(stderr, "gilab: error: %s\n", e.what());
        return kExitError;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "gilab: internal error: %s\n", e.what());
        return kExitError;
    }
    return kExitUsage;
}

}  // namespace gilab::cli
