// libFuzzer target: Mid-360 point/IMU datagrams through one stateful decoder (udp_cnt tracking).
#include <array>
#include <cstddef>
#include <cstdint>

#include "drivers/lidar/mid360.hpp"

using namespace storey::drivers::lidar;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static Mid360Decoder decoder;
  std::array<LidarPoint, kMid360MaxPointsPerPacket> out;
  ImuSample imu;
  const Mid360PacketInfo info = decoder.decode(std::span<const uint8_t>(data, size), out, &imu);
  if (info.reason == DropReason::none && info.points > out.size()) __builtin_trap();
  return 0;
}
