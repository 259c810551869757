#pragma once
// The CRCs of the drivers' wire formats: CRC-16/CCITT-FALSE (Livox SDK2 command headers) and the
// zlib CRC-32 (Livox point payloads, the Go2 UDP link frames, CAN transfers). Table-driven, tables
// built at compile time. Header-only and std-only, so the fuzz targets compile decoders alone.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

namespace storey::drivers {

namespace crc_detail {
constexpr std::array<uint16_t, 256> make_crc16_table() {
  std::array<uint16_t, 256> t{};
  for (uint32_t i = 0; i < 256; ++i) {
    uint16_t c = static_cast<uint16_t>(i << 8);
    for (int k = 0; k < 8; ++k)
      c = (c & 0x8000) ? static_cast<uint16_t>((c << 1) ^ 0x1021) : static_cast<uint16_t>(c << 1);
    t[i] = c;
  }
  return t;
}
constexpr std::array<uint32_t, 256> make_crc32_table() {
  std::array<uint32_t, 256> t{};
  for (uint32_t i = 0; i < 256; ++i) {
    uint32_t c = i;
    for (int k = 0; k < 8; ++k) c = (c & 1u) ? (c >> 1) ^ 0xEDB88320u : c >> 1;
    t[i] = c;
  }
  return t;
}
inline constexpr auto kCrc16Table = make_crc16_table();
inline constexpr auto kCrc32Table = make_crc32_table();
}  // namespace crc_detail

// CRC-16/CCITT-FALSE: poly 0x1021, init 0xFFFF, no reflection, no final xor. Check 0x29B1.
constexpr uint16_t crc16_ccitt_false(std::span<const uint8_t> data, uint16_t crc = 0xFFFF) {
  for (uint8_t b : data) {
    crc = static_cast<uint16_t>((crc << 8) ^ crc_detail::kCrc16Table[((crc >> 8) ^ b) & 0xFF]);
  }
  return crc;
}

// CRC-32 as zlib's crc32(): reflected poly 0xEDB88320, init and final xor 0xFFFFFFFF.
// Check 0xCBF43926. `prev` chains calls like zlib (pass the previous result).
constexpr uint32_t crc32_zlib(std::span<const uint8_t> data, uint32_t prev = 0) {
  uint32_t c = ~prev;
  for (uint8_t b : data) c = crc_detail::kCrc32Table[(c ^ b) & 0xFF] ^ (c >> 8);
  return ~c;
}

}  // namespace storey::drivers
