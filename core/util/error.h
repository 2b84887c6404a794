#pragma once
/** The project's exception type: a message that names the file, key or object at fault. */
#include <stdexcept>
#include <string>

namespace gilab {

class Error : public std::runtime_error {
public:
    explicit Error(const std::string& message) : std::runtime_error(message) {}
};

/** A request above one of this device's limits (a buffer over maxStorageBufferRange, say): the
 *  parameters are valid, this device cannot run them. An experiment records such a run as
 *  unsupported, with the message as its reason, and goes on with the others. */
class DeviceLimitError : public Error {
public:
    using Error::Error;
};

}  // namespace gilab
