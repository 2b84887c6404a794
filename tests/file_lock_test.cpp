// FileLock (core/util/file_lock.h): the cross-process lock the shared results folder and the
// reference cache rely on (docs/cluster.md).
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <thread>

#include <gtest/gtest.h>

#include "core/util/error.h"
#include "core/util/file_lock.h"
#include "tests/temp_dir.h"

namespace gilab {
namespace {

using test::TempDir;

/** Forks a child that takes the lock, reports through a pipe, then sleeps until killed. */
pid_t forkHolder(const std::filesystem::path& path) {
    int fds[2];
    if (::pipe(fds) != 0) return -1;
    const pid_t pid = ::fork();
    if (pid == 0) {
        ::close(fds[0]);
        std::optional<FileLock> lock = FileLock::tryAcquire(path);
        const char ok = lock ? 'y' : 'n';
        if (::write(fds[1], &ok, 1) != 1) ::_exit(2);
        for (;;)
            ::pause();
    }
    ::close(fds[1]);
    char ok = 0;
    const bool got = ::read(fds[0], &ok, 1) == 1 && ok == 'y';
    ::close(fds[0]);
    return got ? pid : -1;
}

TEST(CpuFileLock, AnotherProcessCannotTakeAHeldLockUntilTheHolderIsKilled) {
    TempDir tmp;
    const auto path = tmp.path() / "locks" / "a.lock";
    const pid_t holder = forkHolder(path);
    ASSERT_GT(holder, 0);
    EXPECT_FALSE(FileLock::tryAcquire(path));
    ::kill(holder, SIGKILL);  // no clean-up runs: the kernel drops the lock
    ::waitpid(holder, nullptr, 0);
    EXPECT_TRUE(FileLock::tryAcquire(path));
}

TEST(CpuFileLock, ReleasedWhenDestroyedAndMovable) {
    TempDir tmp;
    const auto path = tmp.path() / "b.lock";
    {
        std::optional<FileLock> a = FileLock::tryAcquire(path);
        ASSERT_TRUE(a);
        FileLock moved = std::move(*a);
        a.reset();  // the moved-from lock owns nothing: still held by `moved`
        EXPECT_FALSE(FileLock::tryAcquire(path));
        EXPECT_EQ(moved.path(), path);
    }
    EXPECT_TRUE(FileLock::tryAcquire(path));
}

TEST(CpuFileLock, AcquireWaitsForTheHolderAndSaysSoOnce) {
    TempDir tmp;
    const auto path = tmp.path() / "c.lock";
    std::optional<FileLock> held = FileLock::tryAcquire(path);
    ASSERT_TRUE(held);
    std::thread releaser([&] {
        std::this_thread::sleep_for(std::chrono::milliseconds(300));
        held.reset();
    });
    int waits = 0;
    const auto start = std::chrono::steady_clock::now();
    std::optional<FileLock> got = FileLock::acquire(path, nullptr, [&] { ++waits; });
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    releaser.join();
    EXPECT_TRUE(got);
    EXPECT_EQ(waits, 1);
    EXPECT_GE(seconds, 0.25);
}

TEST(CpuFileLock, AcquireStopsWhenCancelled) {
    TempDir tmp;
    const auto path = tmp.path() / "d.lock";
    std::optional<FileLock> held = FileLock::tryAcquire(path);
    ASSERT_TRUE(held);
    std::atomic<bool> cancel{false};
    std::thread canceller([&] {
        std::this_thread::sleep_for(std::chrono::milliseconds(200));
        cancel = true;
    });
    EXPECT_FALSE(FileLock::acquire(path, &cancel));
    canceller.join();
}

TEST(CpuFileLock, AnUnusableLockFileIsAnErrorNamingIt) {
    TempDir tmp;
    const auto file = tmp.path() / "plain";
    { std::ofstream(file) << "x"; }
    const auto path = file / "e.lock";  // a "folder" that is a file
    try {
        FileLock::tryAcquire(path);
        FAIL() << "expected an error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos) << e.what();
    }
}

TEST(CpuFileLock, ProcessTagNamesHostAndPid) {
    const std::string tag = processTag();
    const std::string pid = std::string(1, '-').append(std::to_string(::getpid()));
    ASSERT_GT(tag.size(), pid.size());
    EXPECT_EQ(tag.substr(tag.size() - pid.size()), pid);
    EXPECT_EQ(tag.find('/'), std::string::npos);
}

}  // namespace
}  // namespace gilab
