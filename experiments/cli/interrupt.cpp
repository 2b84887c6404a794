#include "experiments/cli/interrupt.h"

#include <unistd.h>

#include <cstring>

namespace gilab::cli {
namespace {

static_assert(std::atomic<bool>::is_always_lock_free, "the SIGINT flag must be lock-free");
std::atomic<bool> g_interrupted{false};
const char* g_message = "";

extern "C" void onGilabInterrupt(int) {
    g_interrupted.store(true);
    [[maybe_unused]] const ssize_t n = ::write(STDERR_FILENO, g_message, std::strlen(g_message));
}

}  // namespace

InterruptScope::InterruptScope(const char* message) {
    g_message = message;
    g_interrupted.store(false);
    struct sigaction action {};
    action.sa_handler = onGilabInterrupt;
    sigemptyset(&action.sa_mask);
    action.sa_flags = SA_RESETHAND;
    sigaction(SIGINT, &action, &m_previous);
}

InterruptScope::~InterruptScope() {
    sigaction(SIGINT, &m_previous, nullptr);
}

const std::atomic<bool>& InterruptScope::flag() const {
    return g_interrupted;
}

}  // namespace gilab::cli
