// Tokens and numbers of the line-based text formats the mesh readers share (OBJ, ASCII
// PLY). Internal to the readers: errors are reported by the caller, which knows the file,
// the line and the field.
#pragma once

#include <string_view>
#include <vector>

namespace subflow::geometry {

// The whitespace-separated tokens of `line` (views into it).
std::vector<std::string_view> SplitTokens(std::string_view line);

// The whole of `token` as a decimal floating-point number (an optional leading '+' is
// accepted, as strtod does). A magnitude beyond double's range gives ±infinity, one below
// its smallest subnormal gives ±0 (std::from_chars reports both as out of range). False
// when the token is not a number, or has anything after it.
bool ParseDouble(std::string_view token, double* value);

// The whole of `token` as a decimal integer (optional leading '+'). False when it is not
// one, or does not fit a long long.
bool ParseInteger(std::string_view token, long long* value);

}  // namespace subflow::geometry
