#pragma once
/**
 * Cross-process exclusive locks on a shared folder (docs/cluster.md, "Shared results folder").
 *
 * A FileLock holds flock(LOCK_EX) on a lock file. The kernel releases it when the holder's file
 * descriptor closes, so it outlives no process: a SIGKILLed holder frees it at once and nothing
 * on disk has to be cleaned up. Lock files are created on demand and never deleted (deleting
 * one while another process waits on it would let two processes hold "the" lock).
 */
#include <atomic>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>

namespace gilab {

class FileLock {
public:
    /** The lock on `path` if no other process holds it, else nullopt. Throws gilab::Error
     *  naming the file when it cannot be created or locked for another reason. */
    static std::optional<FileLock> tryAcquire(const std::filesystem::path& path);
    /**
     * Waits for the lock on `path`, polling every 0.1 s. `onWait` is called once if the lock is
     * busy at first (to say who is waiting for what). Returns nullopt if `cancel` became true
     * while waiting.
     */
    static std::optional<FileLock> acquire(const std::filesystem::path& path,
                                           const std::atomic<bool>* cancel = nullptr,
                                           const std::function<void()>& onWait = {});

    FileLock(FileLock&& other) noexcept;
    FileLock& operator=(FileLock&& other) noexcept;
    FileLock(const FileLock&) = delete;
    FileLock& operator=(const FileLock&) = delete;
    ~FileLock();

    const std::filesystem::path& path() const { return m_path; }

private:
    FileLock(std::filesystem::path path, int fd) : m_path(std::move(path)), m_fd(fd) {}
    std::filesystem::path m_path;
    int m_fd = -1;
};

/** This machine's host name (gethostname), "unknown" if it has none: the node in provenance,
 *  in a run's result.json and in processTag(). */
std::string hostName();

/** "<host>-<pid>": names a process uniquely across the nodes sharing a folder (temporary
 *  files and folders; pids alone repeat from node to node). */
std::string processTag();

}  // namespace gilab
