#pragma once
/**
 * Text files embedded in the binary at build time, looked up by name. cmake/GilabEmbed.cmake
 * generates one static EmbeddedTextRegistration per file, e.g. a technique folder's
 * known_weaknesses.json under "<id>/known_weaknesses.json" (cmake/GilabTechnique.cmake).
 */
#include <optional>
#include <string>
#include <vector>

namespace gilab {

struct EmbeddedTextRegistration {
    EmbeddedTextRegistration(const char* name, const char* text);
};

/** The text registered under `name`, or nothing. */
std::optional<std::string> embeddedText(const std::string& name);
/** Every registered name, sorted. */
std::vector<std::string> embeddedTextNames();

}  // namespace gilab
