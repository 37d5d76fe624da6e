// Little- and big-endian binary writing of 32-bit values, independent of the host's byte
// order (point caches are little-endian PC2 or big-endian MDD).
#pragma once

#include <cstdint>
#include <cstring>
#include <ostream>

namespace subflow::output {

enum class ByteOrder { kLittleEndian, kBigEndian };

// Stores `value` in bytes[0..3] in `order`.
inline void EncodeUint32(std::uint32_t value, ByteOrder order, char* bytes) {
  for (int i = 0; i < 4; ++i) {
    const int shift = order == ByteOrder::kLittleEndian ? 8 * i : 8 * (3 - i);
    bytes[i] = static_cast<char>((value >> shift) & 0xFFu);
  }
}

inline void EncodeFloat32(float value, ByteOrder order, char* bytes) {
  std::uint32_t bits;
  std::memcpy(&bits, &value, 4);
  EncodeUint32(bits, order, bytes);
}

inline void WriteUint32(std::ostream& out, std::uint32_t value, ByteOrder order) {
  char bytes[4];
  EncodeUint32(value, order, bytes);
  out.write(bytes, 4);
}

inline void WriteInt32(std::ostream& out, std::int32_t value, ByteOrder order) {
  WriteUint32(out, static_cast<std::uint32_t>(value), order);
}

inline void WriteFloat32(std::ostream& out, float value, ByteOrder order) {
  char bytes[4];
  EncodeFloat32(value, order, bytes);
  out.write(bytes, 4);
}

}  // namespace subflow::output
