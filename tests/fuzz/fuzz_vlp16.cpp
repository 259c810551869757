// libFuzzer target: VLP-16 data and position packets (any bytes must be refused or decoded,
// never crash, never write past the point buffer).
#include <array>
#include <cstddef>
#include <cstdint>

#include "drivers/lidar/vlp16.hpp"

using namespace storey::drivers::lidar;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static Vlp16Decoder decoder;
  std::array<LidarPoint, kVlp16MaxPointsPerPacket> out;
  std::span<const uint8_t> in(data, size);
  const Vlp16PacketInfo info = decoder.decode(in, out);
  if (info.reason == DropReason::none && info.points > out.size()) __builtin_trap();
  Vlp16Position pos;
  (void)vlp16_decode_position(in, pos);
  (void)parse_nmea_rmc(std::span<const char>(reinterpret_cast<const char*>(data), size));
  return 0;
}
