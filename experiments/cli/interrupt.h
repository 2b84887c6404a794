#pragma once
/**
 * Ctrl-C for long commands: the first SIGINT sets a flag that the work checks at its next safe
 * point (a reference batch, a run boundary) and saves what it has; SA_RESETHAND restores the
 * default action, so a second Ctrl-C kills at once.
 */
#include <atomic>
#include <csignal>
#include <string>

namespace gilab::cli {

class InterruptScope {
public:
    /** `message` is printed (async-signal-safely) on the first Ctrl-C. */
    explicit InterruptScope(const char* message);
    ~InterruptScope();
    InterruptScope(const InterruptScope&) = delete;
    InterruptScope& operator=(const InterruptScope&) = delete;

    const std::atomic<bool>& flag() const;
    bool interrupted() const { return flag().load(); }

private:
    struct sigaction m_previous {};
};

/** Exit code of a command stopped by Ctrl-C (128 + SIGINT, the shell's convention). */
inline constexpr int kExitInterrupted = 130;

}  // namespace gilab::cli
