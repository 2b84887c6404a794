#pragma once
/**
 * Ctrl-C and SIGTERM for long commands: the first SIGINT or SIGTERM (what a cluster scheduler
 * sends at a job's time limit) sets a flag that the work checks at its next safe point (a
 * reference batch, a run boundary) and saves what it has. The handler then restores the default
 * action of both signals, so a second one kills at once.
 */
#include <atomic>
#include <csignal>
#include <string>

namespace gilab::cli {

class InterruptScope {
public:
    /** `message` is printed (async-signal-safely) on the first SIGINT or SIGTERM. */
    explicit InterruptScope(const char* message);
    ~InterruptScope();
    InterruptScope(const InterruptScope&) = delete;
    InterruptScope& operator=(const InterruptScope&) = delete;

    const std::atomic<bool>& flag() const;
    bool interrupted() const { return flag().load(); }
    /** The signal that interrupted (SIGINT or SIGTERM), 0 if none. */
    int signal() const;

private:
    struct sigaction m_previousInt {};
    struct sigaction m_previousTerm {};
};

/** Exit code of a command stopped by Ctrl-C or SIGTERM (128 + SIGINT, the shell's convention
 *  for Ctrl-C; SIGTERM is reported the same way, as "interrupted, partial result saved"). */
inline constexpr int kExitInterrupted = 130;

}  // namespace gilab::cli
