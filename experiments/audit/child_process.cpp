#include "experiments/audit/child_process.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <fstream>
#include <thread>

#include "core/util/error.h"

namespace gilab::audit {

namespace fs = std::filesystem;

std::string selfExecutable() {
    // The link itself, not its target: it runs this very binary even after a rebuild replaced
    // (deleted) the file, so every cell of one audit runs the same code.
    if (!fs::exists("/proc/self/exe")) throw Error("audit: /proc/self/exe is not available");
    return "/proc/self/exe";
}

ChildExit runChild(const std::vector<std::string>& args, const fs::path& log, double timeoutS,
                   const std::atomic<bool>* cancel) {
    fs::create_directories(log.parent_path());
    const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
    if (fd < 0) throw Error(log.string() + ": cannot open for writing: " + std::strerror(errno));
    std::vector<std::string> copy = args;
    std::vector<char*> argv;
    for (std::string& a : copy)
        argv.push_back(a.data());
    argv.push_back(nullptr);
    const auto start = std::chrono::steady_clock::now();
    const pid_t pid = ::fork();
    if (pid < 0) {
        ::close(fd);
        throw Error("audit: cannot start " + args[0] + ": " + std::strerror(errno));
    }
    if (pid == 0) {
        ::dup2(fd, STDOUT_FILENO);
        ::dup2(fd, STDERR_FILENO);
        ::execv(argv[0], argv.data());
        std::fprintf(stderr, "gilab: error: cannot run %s: %s\n", argv[0], std::strerror(errno));
        std::_Exit(127);
    }
    ::close(fd);
    ChildExit out;
    auto elapsed = [&] {
        return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    };
    double termSentAt = -1.0;
    int status = 0;
    for (;;) {
        const pid_t r = ::waitpid(pid, &status, WNOHANG);
        if (r == pid) break;
        if (r < 0 && errno != EINTR)
            throw Error("audit: waitpid failed: " + std::string(std::strerror(errno)));
        const double t = elapsed();
        const bool stop = (cancel && cancel->load()) || t > timeoutS;
        if (stop && termSentAt < 0.0) {
            out.timedOut = t > timeoutS;
            out.cancelled = !out.timedOut;
            ::kill(pid, SIGTERM);
            termSentAt = t;
        } else if (termSentAt >= 0.0 && t - termSentAt > 10.0) {
            ::kill(pid, SIGKILL);
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    out.seconds = elapsed();
    if (WIFEXITED(status)) {
        out.exited = true;
        out.code = WEXITSTATUS(status);
    } else if (WIFSIGNALED(status)) {
        out.signal = WTERMSIG(status);
    }
    return out;
}

std::string lastErrorLine(const fs::path& log) {
    std::ifstream in(log);
    std::string line, last, error;
    const std::string prefix = "gilab: error: ";
    while (std::getline(in, line)) {
        if (line.empty()) continue;
        last = line;
        if (line.rfind(prefix, 0) == 0) error = line.substr(prefix.size());
    }
    return error.empty() ? last : error;
}

}  // namespace gilab::audit
