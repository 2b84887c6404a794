#pragma once
/**
 * A progress line on stderr for anything that may take more than a second. On a terminal it
 * redraws one line; otherwise it prints at most one line per second, so logs stay readable.
 */
#include <chrono>
#include <string>

namespace gilab {

class Progress {
public:
    /** `total` = 0 for work of unknown length. Nothing is shown during the first second. */
    Progress(std::string label, size_t total = 0);
    ~Progress();
    void update(size_t done, const std::string& detail = "");
    void finish(const std::string& detail = "");

    static void setQuiet(bool quiet);

private:
    void print(bool final);
    std::string m_label;
    size_t m_total = 0;
    size_t m_done = 0;
    std::string m_detail;
    std::chrono::steady_clock::time_point m_start;
    std::chrono::steady_clock::time_point m_lastPrint;
    bool m_shown = false;
    bool m_finished = false;
};

/** Wall-clock stopwatch in milliseconds. */
class Stopwatch {
public:
    Stopwatch() : m_start(std::chrono::steady_clock::now()) {}
    double elapsedMs() const {
        return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - m_start)
            .count();
    }
    void restart() { m_start = std::chrono::steady_clock::now(); }

private:
    std::chrono::steady_clock::time_point m_start;
};

/** CPU time of the whole process (every thread, user + system) in seconds. */
double processCpuSeconds();

}  // namespace gilab
