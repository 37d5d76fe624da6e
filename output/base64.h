// Base64 (RFC 4648, with padding) of raw bytes: how the viewer page carries its binary
// arrays inside JSON.
#pragma once

#include <cstddef>
#include <string>

namespace subflow::output {

inline std::string Base64(const void* data, std::size_t size) {
  static const char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  const auto* bytes = static_cast<const unsigned char*>(data);
  std::string text;
  text.reserve((size + 2) / 3 * 4);
  for (std::size_t i = 0; i < size; i += 3) {
    const unsigned value = bytes[i] << 16 | (i + 1 < size ? bytes[i + 1] << 8 : 0) | (i + 2 < size ? bytes[i + 2] : 0);
    text += kAlphabet[(value >> 18) & 63];
    text += kAlphabet[(value >> 12) & 63];
    text += i + 1 < size ? kAlphabet[(value >> 6) & 63] : '=';
    text += i + 2 < size ? kAlphabet[value & 63] : '=';
  }
  return text;
}

}  // namespace subflow::output
