#pragma once
/** A fresh temporary folder per test (unique per process, test and instance), removed afterwards.
 */
#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>

#include <gtest/gtest.h>

namespace gilab::test {

class TempDir {
public:
    explicit TempDir(const std::string& prefix = "gilab_test") {
        static std::atomic<int> counter{0};
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        std::string name =
            prefix + "_" + std::to_string(::getpid()) + "_" + std::to_string(counter++);
        if (info) name += std::string("_") + info->test_suite_name() + "_" + info->name();
        m_path = std::filesystem::temp_directory_path() / name;
        std::filesystem::remove_all(m_path);
        std::filesystem::create_directories(m_path);
    }
    ~TempDir() {
        std::error_code ec;
        std::filesystem::remove_all(m_path, ec);
    }
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;

    const std::filesystem::path& path() const { return m_path; }
    /** The path of `name` inside the folder. */
    std::string path(const std::string& name) const { return (m_path / name).string(); }
    std::string file(const std::string& name) const { return path(name); }
    /** Writes `text` to `name` (binary) and returns its path. */
    std::string write(const std::string& name, const std::string& text) const {
        const std::string p = path(name);
        std::ofstream(p, std::ios::binary) << text;
        return p;
    }

private:
    std::filesystem::path m_path;
};

}  // namespace gilab::test
