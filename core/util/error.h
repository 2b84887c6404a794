#pragma once
/** The project's one exception type: a message that names the file, key or object at fault. */
#include <stdexcept>
#include <string>

namespace gilab {

class Error : public std::runtime_error {
public:
    explicit Error(const std::string& message) : std::runtime_error(message) {}
};

}  // namespace gilab
