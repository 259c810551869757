#pragma once
// Link-layer -> IPv4 -> UDP parsing of one captured frame. Standard library only (fuzzed alone).
// Link types: Ethernet (with 802.1Q/802.1ad VLAN tags), Linux cooked SLL and SLL2, raw IPv4,
// BSD loopback (NULL/LOOP). IPv6 and IP fragments are counted and skipped: LiDAR datagrams
// (<= 1380 bytes) never fragment on a 1500-byte MTU, so reassembly is not worth its state.
#include <cstdint>
#include <span>

namespace storey::drivers::pcap {

// Link types as numbered in pcap files (LINKTYPE_*) and by libpcap (DLT_*).
namespace link {
inline constexpr int kNull = 0;
inline constexpr int kEthernet = 1;
inline constexpr int kRawDlt = 12;    // DLT_RAW on Linux
inline constexpr int kRawDlt14 = 14;  // DLT_RAW on some BSDs
inline constexpr int kRaw = 101;      // LINKTYPE_RAW
inline constexpr int kLoop = 108;
inline constexpr int kLinuxSll = 113;
inline constexpr int kIpv4 = 228;
inline constexpr int kLinuxSll2 = 276;
}  // namespace link

struct UdpDatagram {
  uint64_t timestamp_ns = 0;  // capture time
  uint32_t src_addr = 0;      // IPv4, host byte order (192.168.1.200 = 0xC0A801C8)
  uint32_t dst_addr = 0;
  uint16_t src_port = 0;
  uint16_t dst_port = 0;
  std::span<const uint8_t> payload;  // valid until the reader's next call
  // The IPv4 total length claimed more bytes than the frame holds while the UDP length fitted:
  // real VLP-16 position packets do this (IP length 1234 copied from the data packets, UDP
  // length 520). The datagram is accepted on its UDP length and the quirk counted.
  bool ip_length_mismatch = false;
};

enum class FrameResult : uint8_t {
  udp,  // `out` filled
  unsupported_link,
  not_ipv4,  // ARP, IPv6, ...
  not_udp,
  ip_fragment,  // counted and skipped
  truncated,    // captured bytes shorter than the headers say (snaplen or damage)
  malformed,    // header fields impossible (IHL < 5, UDP length < 8, ...)
};

// Parses one frame; `out.payload` points into `frame`.
FrameResult parse_udp_frame(int link_type, std::span<const uint8_t> frame, UdpDatagram& out);

struct FrameStats {
  uint64_t frames = 0, udp = 0, port_filtered = 0, unsupported_link = 0, not_ipv4 = 0, not_udp = 0,
           ip_fragments = 0, truncated = 0, malformed = 0, ip_length_mismatch = 0;
  void count(FrameResult r);
};

}  // namespace storey::drivers::pcap
