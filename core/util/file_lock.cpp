#include "core/util/file_lock.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <thread>

#include "core/util/error.h"

namespace gilab {
namespace {

/** Opens (creating) the lock file and tries flock once: fd and whether it is locked. */
std::pair<int, bool> openAndTry(const std::filesystem::path& path) {
    std::error_code ec;
    std::filesystem::create_directories(path.parent_path(), ec);
    const int fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd < 0)
        throw Error("cannot open the lock file " + path.string() + ": " + std::strerror(errno));
    if (::flock(fd, LOCK_EX | LOCK_NB) == 0) return {fd, true};
    const int err = errno;
    if (err == EWOULDBLOCK || err == EINTR) return {fd, false};
    ::close(fd);
    throw Error("cannot lock " + path.string() + ": " + std::strerror(err) +
                " (docs/cluster.md: file systems without working locks)");
}

}  // namespace

std::optional<FileLock> FileLock::tryAcquire(const std::filesystem::path& path) {
    const auto [fd, locked] = openAndTry(path);
    if (locked) return FileLock(path, fd);
    ::close(fd);
    return std::nullopt;
}

std::optional<FileLock> FileLock::acquire(const std::filesystem::path& path,
                                          const std::atomic<bool>* cancel,
                                          const std::function<void()>& onWait) {
    auto [fd, locked] = openAndTry(path);
    if (!locked && onWait) onWait();
    while (!locked) {
        if (cancel && cancel->load()) {
            ::close(fd);
            return std::nullopt;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
        if (::flock(fd, LOCK_EX | LOCK_NB) == 0) {
            locked = true;
        } else if (errno != EWOULDBLOCK && errno != EINTR) {
            const int err = errno;
            ::close(fd);
            throw Error("cannot lock " + path.string() + ": " + std::strerror(err));
        }
    }
    return FileLock(path, fd);
}

FileLock::FileLock(FileLock&& other) noexcept : m_path(std::move(other.m_path)), m_fd(other.m_fd) {
    other.m_fd = -1;
}

FileLock& FileLock::operator=(FileLock&& other) noexcept {
    if (this != &other) {
        if (m_fd >= 0) ::close(m_fd);
        m_path = std::move(other.m_path);
        m_fd = other.m_fd;
        other.m_fd = -1;
    }
    return *this;
}

FileLock::~FileLock() {
    if (m_fd >= 0) ::close(m_fd);  // closing the descriptor releases the flock
}

std::string hostName() {
    char host[256] = {};
    return ::gethostname(host, sizeof host - 1) == 0 && host[0] ? std::string(host) : "unknown";
}

std::string processTag() {
    std::string tag;
    for (char c : hostName()) {
        if (c == '.') break;  // the short name
        tag += (std::isalnum(static_cast<unsigned char>(c)) || c == '-') ? c : '_';
    }
    return tag + "-" + std::to_string(::getpid());
}

}  // namespace gilab
