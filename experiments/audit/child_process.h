#pragma once
/** A command run as a child process with its output in a log file, a time limit and a cancel
 *  flag (the audit's cells: a crash or a hang of one is recorded, not shared). */
#include <atomic>
#include <filesystem>
#include <string>
#include <vector>

namespace gilab::audit {

struct ChildExit {
    bool exited = false;  // exited normally with `code`
    int code = 0;
    int signal = 0;  // the signal that ended it (crash), 0 if none
    bool timedOut = false;
    bool cancelled = false;
    double seconds = 0.0;
};

/**
 * Runs `args` (args[0]: the executable's path) with stdout and stderr appended to `log`.
 * After `timeoutS` seconds, or once `*cancel` is set, the child gets SIGTERM (it saves what it
 * has) and SIGKILL 10 s later. Throws gilab::Error when the child cannot be started.
 */
ChildExit runChild(const std::vector<std::string>& args, const std::filesystem::path& log,
                   double timeoutS, const std::atomic<bool>* cancel);

/** The running executable, as "/proc/self/exe" (the same binary even if since replaced). */
std::string selfExecutable();

/** The last line of `log` that starts with "gilab: error: " (without it), or its last line. */
std::string lastErrorLine(const std::filesystem::path& log);

}  // namespace gilab::audit
