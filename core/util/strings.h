#pragma once
/** Small string helpers shared by config parsing and messages. */
#include <string>
#include <string_view>
#include <vector>

namespace gilab {

/** Copy without leading and trailing ASCII whitespace. */
std::string trimString(std::string_view text);
/** ASCII lower-case copy. */
std::string toLowerAscii(std::string_view text);
/** "a, b, c" style join. */
std::string joinStrings(const std::vector<std::string>& parts, std::string_view separator);
/** Levenshtein distance (insert, delete, substitute each cost 1). */
size_t editDistance(std::string_view a, std::string_view b);
/**
 * The candidate closest to `word` by edit distance, or "" when none is plausibly a typo
 * (distance above max(2, word.size() / 3)). Ties go to the earliest candidate.
 */
std::string findClosestMatch(std::string_view word, const std::vector<std::string>& candidates);
/** Shortest text that parses back to exactly `value` (std::to_chars), e.g. "0.5", "1e+20". */
std::string formatShortest(double value);

}  // namespace gilab
