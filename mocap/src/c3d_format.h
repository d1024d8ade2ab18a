#pragma once
// Private: the number formats of the C3D file (shared by reader and writer).
//
// A C3D file is a sequence of 512-byte blocks: the header (block 1), the
// parameter section (starting at the block named by header byte 0), and the
// data section (starting at the block named by POINT:DATA_START). Multi-byte
// numbers are stored in the format of the "processor" named in byte 4 of the
// parameter section: 84 Intel, 85 DEC, 86 MIPS/SGI.
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

namespace ccsrm::mocap::internal {

constexpr std::size_t kC3dBlockSize = 512;
constexpr std::uint8_t kC3dMagic = 0x50;  // header byte 1: 'P', "3D points"

enum class C3dProcessor { kIntel, kDec, kMips };

constexpr std::uint8_t kProcessorIntel = 84;
constexpr std::uint8_t kProcessorDec = 85;
constexpr std::uint8_t kProcessorMips = 86;

// 16-bit word: little-endian on Intel and DEC, big-endian on MIPS.
inline std::uint16_t DecodeU16(const std::uint8_t* p, C3dProcessor processor) {
  if (processor == C3dProcessor::kMips) {
    return static_cast<std::uint16_t>((p[0] << 8) | p[1]);
  }
  return static_cast<std::uint16_t>(p[0] | (p[1] << 8));
}

inline std::int16_t DecodeI16(const std::uint8_t* p, C3dProcessor processor) {
  return static_cast<std::int16_t>(DecodeU16(p, processor));
}

// 32-bit float.
//  - Intel: IEEE-754 single, little-endian.
//  - MIPS: IEEE-754 single, big-endian.
//  - DEC: VAX F-float stored as two little-endian 16-bit words, the first
//    holding the sign (bit 15), the 8-bit exponent (bits 14..7) and the top 7
//    mantissa bits; the second the low 16 mantissa bits. Value
//    = (-1)^s × 0.1m (binary, hidden leading 1 after the point) × 2^(e-128),
//    i.e. the IEEE value of the same bits divided by 4. We decode it exactly
//    with ldexp rather than by dividing an IEEE reinterpretation, because the
//    IEEE view turns VAX exponent 255 (a valid number) into Inf/NaN. Exponent
//    0 is zero (sign 0) or a "reserved operand" (sign 1), returned as NaN.
inline float DecodeF32(const std::uint8_t* p, C3dProcessor processor) {
  std::uint32_t bits = 0;
  switch (processor) {
    case C3dProcessor::kIntel:
      bits = static_cast<std::uint32_t>(p[0]) | (static_cast<std::uint32_t>(p[1]) << 8) |
             (static_cast<std::uint32_t>(p[2]) << 16) | (static_cast<std::uint32_t>(p[3]) << 24);
      break;
    case C3dProcessor::kMips:
      bits = (static_cast<std::uint32_t>(p[0]) << 24) | (static_cast<std::uint32_t>(p[1]) << 16) |
             (static_cast<std::uint32_t>(p[2]) << 8) | static_cast<std::uint32_t>(p[3]);
      break;
    case C3dProcessor::kDec: {
      const std::uint32_t vax =
          (static_cast<std::uint32_t>(p[1]) << 24) | (static_cast<std::uint32_t>(p[0]) << 16) |
          (static_cast<std::uint32_t>(p[3]) << 8) | static_cast<std::uint32_t>(p[2]);
      const bool negative = (vax >> 31) != 0;
      const int exponent = static_cast<int>((vax >> 23) & 0xFF);
      const std::uint32_t mantissa = vax & 0x7FFFFF;
      if (exponent == 0) {
        return negative ? std::numeric_limits<float>::quiet_NaN() : 0.0f;
      }
      // 0.1m × 2^(e-128) = (2^23 + m) × 2^(e-128-24).
      const double magnitude =
          std::ldexp(static_cast<double>(0x800000u | mantissa), exponent - 128 - 24);
      return static_cast<float>(negative ? -magnitude : magnitude);
    }
  }
  float value = 0.0f;
  std::memcpy(&value, &bits, sizeof(value));
  return value;
}

// Writers (Intel only: the writer always writes Intel files).
inline void EncodeIntelU16(std::uint16_t value, std::uint8_t* p) {
  p[0] = static_cast<std::uint8_t>(value & 0xFF);
  p[1] = static_cast<std::uint8_t>(value >> 8);
}

inline void EncodeIntelF32(float value, std::uint8_t* p) {
  std::uint32_t bits = 0;
  std::memcpy(&bits, &value, sizeof(bits));
  for (int i = 0; i < 4; ++i) p[i] = static_cast<std::uint8_t>((bits >> (8 * i)) & 0xFF);
}

}  // namespace ccsrm::mocap::internal
