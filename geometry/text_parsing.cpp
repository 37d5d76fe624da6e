#include "geometry/text_parsing.h"

#include <cctype>
#include <charconv>
#include <cstdlib>
#include <string>

namespace subflow::geometry {

std::vector<std::string_view> SplitTokens(std::string_view line) {
  std::vector<std::string_view> tokens;
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && std::isspace(static_cast<unsigned char>(line[i]))) ++i;
    size_t j = i;
    while (j < line.size() && !std::isspace(static_cast<unsigned char>(line[j]))) ++j;
    if (j > i) tokens.push_back(line.substr(i, j - i));
    i = j;
  }
  return tokens;
}

bool ParseDouble(std::string_view token, double* value) {
  if (!token.empty() && token[0] == '+') token.remove_prefix(1);  // from_chars rejects '+'
  const char* end = token.data() + token.size();
  const auto result = std::from_chars(token.data(), end, *value);
  if (result.ptr != end) return false;
  if (result.ec == std::errc::result_out_of_range) {
    // A well-formed number too large or too small: strtod rounds it to ±HUGE_VAL (= ±inf)
    // or to the nearest subnormal / ±0, which from_chars leaves to the caller.
    *value = std::strtod(std::string(token).c_str(), nullptr);
    return true;
  }
  return result.ec == std::errc();
}

bool ParseInteger(std::string_view token, long long* value) {
  if (!token.empty() && token[0] == '+') token.remove_prefix(1);
  const char* end = token.data() + token.size();
  const auto result = std::from_chars(token.data(), end, *value);
  return result.ec == std::errc() && result.ptr == end;
}

}  // namespace subflow::geometry
