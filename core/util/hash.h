#pragma once
/** Content hashes for cache and run keys: XXH3-128 (libxxhash), as 32 lower-case hex digits. */
#include <string>
#include <string_view>

namespace gilab {

std::string hashHex128(std::string_view bytes);

}  // namespace gilab
