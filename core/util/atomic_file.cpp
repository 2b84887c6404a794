#include "core/util/atomic_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <fstream>

#include "core/util/error.h"
#include "core/util/file_lock.h"

namespace gilab {

void writeFileAtomic(const std::filesystem::path& path, const std::string& contents) {
    const std::filesystem::path tmp = path.string() + ".tmp-" + processTag();
    {
        std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
        out << contents;
        out.flush();
        if (!out) throw Error("cannot write " + tmp.string());
    }
    const int fd = ::open(tmp.c_str(), O_RDONLY);
    if (fd >= 0) {
        ::fsync(fd);
        ::close(fd);
    }
    std::error_code ec;
    std::filesystem::rename(tmp, path, ec);
    if (ec) {
        std::filesystem::remove(tmp);
        throw Error("cannot rename " + tmp.string() + " to " + path.string() + ": " + ec.message());
    }
}

}  // namespace gilab
