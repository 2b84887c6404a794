#pragma once
/** Internal to core/image: atomic image-file writing through OpenImageIO. */
#include <string>

#include <OpenImageIO/imageio.h>

namespace gilab::detail {

/** "<path>.tmp-<pid>": the temporary file an atomic write goes through. */
std::string temporaryPathFor(const std::string& path);

/**
 * Writes `pixels` (laid out as `spec` says, in `spec.format`) with the OpenImageIO plugin
 * `formatName` ("openexr", "png") to a temporary file next to `path`, then renames it over
 * `path`. On failure the temporary file is removed and gilab::Error names `path`.
 */
void writeImageAtomic(const std::string& path, const char* formatName, const OIIO::ImageSpec& spec,
                      const void* pixels);

}  // namespace gilab::detail
