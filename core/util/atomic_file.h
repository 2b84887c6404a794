#pragma once
/** Durable, atomic file writes: a killed process never leaves a half-written file in place. */
#include <filesystem>
#include <string>

namespace gilab {

/** Writes to "<path>.tmp-<host>-<pid>", flushes and fsyncs it, then renames it over `path`. */
void writeFileAtomic(const std::filesystem::path& path, const std::string& contents);

}  // namespace gilab
