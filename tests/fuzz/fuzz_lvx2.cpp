// libFuzzer target: .lvx2 files -> packages -> SDK2 datagrams -> Mid-360 decoder.
#include <array>
#include <cstdint>

#include "drivers/lidar/mid360.hpp"
#include "drivers/pcap/lvx2_reader.hpp"

using namespace storey::drivers;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  pcap::Lvx2Reader reader;
  if (!reader.open(std::span<const uint8_t>(data, size), nullptr)) return 0;
  lidar::Mid360Decoder dec;
  std::array<uint8_t, 65536> pkt;
  std::array<lidar::LidarPoint, 4096> out;
  pcap::Lvx2Package p;
  for (int i = 0; i < 100000 && reader.next(p); ++i) {
    const std::size_t n = pcap::lvx2_to_sdk_packet(p, 4800, pkt);
    if (n > 0) dec.decode(std::span<const uint8_t>(pkt.data(), n), out);
  }
  return 0;
}
