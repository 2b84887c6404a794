#include "experiments/cli/interrupt.h"

#include <unistd.h>

#include <cstring>

namespace gilab::cli {
namespace {

static_assert(std::atomic<bool>::is_always_lock_free, "the interrupt flag must be lock-free");
static_assert(std::atomic<int>::is_always_lock_free, "the interrupt signal must be lock-free");
std::atomic<bool> g_interrupted{false};
std::atomic<int> g_signal{0};
const char* g_message = "";

extern "C" void onGilabInterrupt(int sig) {
    // Only async-signal-safe calls: the second SIGINT or SIGTERM kills at once
    struct sigaction fallback {};
    fallback.sa_handler = SIG_DFL;
    sigemptyset(&fallback.sa_mask);
    sigaction(SIGINT, &fallback, nullptr);
    sigaction(SIGTERM, &fallback, nullptr);
    g_signal.store(sig);
    g_interrupted.store(true);
    [[maybe_unused]] const ssize_t n = ::write(STDERR_FILENO, g_message, std::strlen(g_message));
}

}  // namespace

InterruptScope::InterruptScope(const char* message) {
    g_message = message;
    g_interrupted.store(false);
    g_signal.store(0);
    struct sigaction action {};
    action.sa_handler = onGilabInterrupt;
    sigemptyset(&action.sa_mask);
    sigaddset(&action.sa_mask, SIGINT);  // one handler at a time
    sigaddset(&action.sa_mask, SIGTERM);
    action.sa_flags = 0;
    sigaction(SIGINT, &action, &m_previousInt);
    sigaction(SIGTERM, &action, &m_previousTerm);
}

InterruptScope::~InterruptScope() {
    sigaction(SIGINT, &m_previousInt, nullptr);
    sigaction(SIGTERM, &m_previousTerm, nullptr);
}

const std::atomic<bool>& InterruptScope::flag() const {
    return g_interrupted;
}

int InterruptScope::signal() const {
    return g_signal.load();
}

}  // namespace gilab::cli
