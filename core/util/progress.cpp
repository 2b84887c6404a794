#include "core/util/progress.h"

#include <time.h>
#include <unistd.h>

#include <cstdio>

namespace gilab {
namespace {
bool g_quiet = false;
bool isTerminal() {
    static const bool tty = isatty(fileno(stderr)) != 0;
    return tty;
}
double seconds(std::chrono::steady_clock::duration d) {
    return std::chrono::duration<double>(d).count();
}
}  // namespace

void Progress::setQuiet(bool quiet) {
    g_quiet = quiet;
}

Progress::Progress(std::string label, size_t total)
    : m_label(std::move(label)),
      m_total(total),
      m_start(std::chrono::steady_clock::now()),
      m_lastPrint(m_start) {}

Progress::~Progress() {
    if (!m_finished) finish();
}

void Progress::update(size_t done, const std::string& detail) {
    m_done = done;
    m_detail = detail;
    const auto now = std::chrono::steady_clock::now();
    if (seconds(now - m_start) < 1.0) return;
    if (!isTerminal() && m_shown && seconds(now - m_lastPrint) < 1.0) return;
    m_lastPrint = now;
    print(false);
}

void Progress::finish(const std::string& detail) {
    m_finished = true;
    if (!detail.empty()) m_detail = detail;
    if (m_shown) print(true);
}

void Progress::print(bool final) {
    if (g_quiet) return;
    m_shown = true;
    const double elapsed = seconds(std::chrono::steady_clock::now() - m_start);
    char counts[96] = "";
    if (m_total > 0) {
        const double frac = double(m_done) / double(m_total);
        const double eta = frac > 0.0 ? elapsed * (1.0 - frac) / frac : 0.0;
        std::snprintf(counts, sizeof counts, " %zu/%zu (%.0f%%) eta %.1fs", m_done, m_total,
                      100.0 * frac, final ? 0.0 : eta);
    }
    std::fprintf(stderr, "%s[gilab] %s%s %.1fs %s%s", isTerminal() ? "\r\033[K" : "",
                 m_label.c_str(), counts, elapsed, m_detail.c_str(),
                 (final || !isTerminal()) ? "\n" : "");
    std::fflush(stderr);
}

double processCpuSeconds() {
    timespec t{};
    if (clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t) != 0) return 0.0;
    return double(t.tv_sec) + double(t.tv_nsec) * 1e-9;
}

}  // namespace gilab
