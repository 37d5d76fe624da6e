// Errors of subflow: every bad input is reported by throwing subflow::Error whose
// message names the file, the field and what was expected, so the CLI can print it
// in one line and exit non-zero.
#pragma once

#include <stdexcept>
#include <string>

namespace subflow {

class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Builds the one-line message "<source>: <field>: <problem>" and throws it.
// `source` is usually a file path; `field` the entry, line or element concerned.
[[noreturn]] inline void ThrowError(const std::string& source, const std::string& field,
                                    const std::string& problem) {
  std::string message = source;
  if (!field.empty()) message += (message.empty() ? "" : ": ") + field;
  message += (message.empty() ? "" : ": ") + problem;
  throw Error(message);
}

}  // namespace subflow

// Internal invariants: stay on in every build type (tests rely on them), and say where.
#define SUBFLOW_CHECK(condition, message)                                               \
  do {                                                                                  \
    if (!(condition))                                                                   \
      throw ::subflow::Error(std::string(__FILE__) + ":" + std::to_string(__LINE__) +   \
                             ": check failed: " #condition ": " + std::string(message)); \
  } while (false)
