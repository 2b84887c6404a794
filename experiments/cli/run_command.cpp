// `gilab run CONFIG` and `gilab report DIR`.
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "core/util/build_info.h"
#include "core/util/error.h"
#include "experiments/cli/cli.h"
#include "experiments/cli/interrupt.h"
#include "experiments/runner/runner.h"

namespace gilab::cli {

int runExitCode(const exp::RunnerSummary& s, bool interrupted) {
    if (s.cancelled || interrupted) return kExitInterrupted;
    if (s.invalid > 0 || s.validationOutsideRuns > 0) return kExitInvalid;
    return s.nonfinite ? kExitNonFinite : kExitOk;
}

int runExperimentCommand(const exp::RunnerOptions& options) {
    checkOutputFolder("--out", options.outRoot);  // the experiment's folder goes inside
    InterruptScope interrupt(
        "\ngilab: interrupted: stopping after the current run; finished runs are kept "
        "(a second Ctrl-C or SIGTERM aborts)\n");
    const exp::RunnerSummary s = exp::runExperiment(options, &interrupt.flag());
    if (options.dryRun) return kExitOk;
    if (options.referencesOnly) {
        std::printf("%s: %zu distinct references (%zu in this shard): %zu rendered here%s\n",
                    s.dir.string().c_str(), s.referencesTotal, s.referencesInShard,
                    s.referencesRendered, s.cancelled ? ", interrupted" : "");
        return s.cancelled || interrupt.interrupted() ? kExitInterrupted : kExitOk;
    }
    if (s.rowsRepaired > 0)
        std::printf("%s: %zu finished runs had no row in results.jsonl; added\n",
                    s.dir.string().c_str(), s.rowsRepaired);
    std::printf(
        "%s: %zu runs (%zu in this shard): %zu already finished, %zu finished by another "
        "process, %zu ran (%zu unsupported, %zu with non-finite pixels, %zu invalid)%s\n",
        s.dir.string().c_str(), s.total, s.inShard, s.alreadyFinished, s.doneElsewhere, s.ran,
        s.unsupported, s.nonfinite, s.invalid, s.cancelled ? ", interrupted" : "");
    if (s.invalid > 0)
        std::fprintf(stderr,
                     "gilab: %zu invalid runs: Vulkan validation reported errors or warnings "
                     "(status \"invalid\" in their result.json; redone on the next run)\n",
                     s.invalid);
    std::printf("report: %s report %s\n", runnableGilab().c_str(),
                quoteForShell(s.dir.string()).c_str());
    return runExitCode(s, interrupt.interrupted());
}

/**
 * The folder holding the report's Python package gilab_report (put on PYTHONPATH, run as
 * `python3 -m gilab_report`): GILAB_REPORT_PACKAGE_DIR, else <bin>/../share/gilab (installed),
 * else <bin>/../scripts (a build folder inside the source tree), else the source tree's scripts/
 * the binary was built from.
 */
static std::string findReportPackageDir() {
    const auto holdsPackage = [](const std::filesystem::path& dir) {
        return std::filesystem::exists(dir / "gilab_report" / "__main__.py");
    };
    if (const char* env = std::getenv("GILAB_REPORT_PACKAGE_DIR"); env && *env) {
        if (!holdsPackage(env))
            throw Error("report: GILAB_REPORT_PACKAGE_DIR=" + std::string(env) +
                        " holds no gilab_report/__main__.py");
        return env;
    }
    std::error_code ec;
    const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
    std::vector<std::filesystem::path> tried;
    if (!ec) {
        const std::filesystem::path bin = exe.parent_path();
        tried.push_back(bin / ".." / "share" / "gilab");
        tried.push_back(bin / ".." / "scripts");
    }
    tried.push_back(std::filesystem::path(build::kSourceDir) / "scripts");
    std::string list;
    for (const auto& p : tried) {
        if (holdsPackage(p)) return p.lexically_normal().string();
        list += (list.empty() ? "" : ", ") + (p / "gilab_report").lexically_normal().string();
    }
    throw Error("report: cannot find the report's Python package gilab_report (looked in " + list +
                "); install with `cmake --install` or set GILAB_REPORT_PACKAGE_DIR to "
                "the folder holding gilab_report/");
}

int runReport(const std::vector<std::string>& dirs, const std::string& outDir) {
    for (const std::string& d : dirs)
        if (!std::filesystem::is_directory(d)) throw Error("report: no such results folder: " + d);
    // An audit folder's report is the table `gilab audit` wrote (docs/audit.md)
    if (dirs.size() == 1 &&
        std::filesystem::exists(std::filesystem::path(dirs[0]) / "audit.json") &&
        !std::filesystem::exists(std::filesystem::path(dirs[0]) / "runs")) {
        std::printf(
            "%s is a `gilab audit` folder: its report is %s (table: %s; each cell's run "
            "folder under cells/ takes `gilab report`)\n",
            dirs[0].c_str(), (std::filesystem::path(dirs[0]) / "audit.html").c_str(),
            (std::filesystem::path(dirs[0]) / "audit.md").c_str());
        return kExitOk;
    }
    const std::string packageDir = findReportPackageDir();
    const char* python = "/usr/bin/python3";  // Debian's, with python3-matplotlib
    std::vector<std::string> args{python, "-m", "gilab_report"};
    args.insert(args.end(), dirs.begin(), dirs.end());
    if (!outDir.empty()) {
        args.push_back("--out");
        args.push_back(outDir);
    }
    std::vector<char*> argv;
    for (std::string& a : args)
        argv.push_back(a.data());
    argv.push_back(nullptr);
    // The environment with the package's folder first on PYTHONPATH (built before fork)
    constexpr std::string_view kKey = "PYTHONPATH=";
    std::vector<std::string> env;
    std::string pythonPath(kKey);
    pythonPath.append(packageDir);
    for (char** e = environ; *e; ++e) {
        const std::string_view entry = *e;
        if (entry.starts_with(kKey)) {
            if (entry.size() > kKey.size()) {
                pythonPath.push_back(':');
                pythonPath.append(entry.substr(kKey.size()));
            }
        } else {
            env.emplace_back(entry);
        }
    }
    env.push_back(pythonPath);
    std::vector<char*> envp;
    for (std::string& e : env)
        envp.push_back(e.data());
    envp.push_back(nullptr);
    std::fflush(stdout);
    const pid_t pid = ::fork();
    if (pid < 0) throw Error("report: cannot start " + std::string(python));
    if (pid == 0) {
        ::execve(python, argv.data(), envp.data());
        std::perror(
            "gilab: report: cannot run /usr/bin/python3 (scripts/install_deps.sh: "
            "python3-matplotlib, python3-jinja2, python3-openimageio)");
        std::_Exit(127);
    }
    int status = 0;
    ::waitpid(pid, &status, 0);
    return WIFEXITED(status) && WEXITSTATUS(status) == 0 ? kExitOk : kExitError;
}

}  // namespace gilab::cli
