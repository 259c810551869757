#include "drivers/pcap/udp_frame.hpp"

namespace storey::drivers::pcap {

namespace {
uint16_t be16(const uint8_t* p) {
  return static_cast<uint16_t>((p[0] << 8) | p[1]);
}
uint32_t be32(const uint8_t* p) {
  return (uint32_t{p[0]} << 24) | (uint32_t{p[1]} << 16) | (uint32_t{p[2]} << 8) | p[3];
}
constexpr uint16_t kEtherIpv4 = 0x0800;
constexpr uint16_t kEtherVlan = 0x8100;
constexpr uint16_t kEtherQinQ = 0x88A8;

FrameResult parse_ipv4(std::span<const uint8_t> b, UdpDatagram& out) {
  if (b.size() < 20) return FrameResult::truncated;
  if ((b[0] >> 4) != 4) return FrameResult::not_ipv4;
  const std::size_t ihl = (b[0] & 0x0F) * 4u;
  if (ihl < 20) return FrameResult::malformed;
  std::size_t total = be16(&b[2]);
  if (total < ihl) return FrameResult::malformed;
  out.ip_length_mismatch = false;
  if (b.size() < total) {
    // Tolerated only when the UDP datagram itself is complete (see UdpDatagram).
    if (b.size() < ihl + 8) return FrameResult::truncated;
    const std::size_t ulen = be16(&b[ihl + 4]);
    if (ulen < 8 || ihl + ulen > b.size()) return FrameResult::truncated;
    out.ip_length_mismatch = true;
    total = ihl + ulen;
  }
  const uint16_t frag = be16(&b[6]);
  if ((frag & 0x2000) != 0 || (frag & 0x1FFF) != 0) return FrameResult::ip_fragment;
  if (b[9] != 17) return FrameResult::not_udp;
  const std::size_t udp_at = ihl;
  if (total < udp_at + 8) return FrameResult::truncated;
  const uint8_t* u = &b[udp_at];
  const std::size_t ulen = be16(u + 4);
  if (ulen < 8) return FrameResult::malformed;
  if (udp_at + ulen > total) return FrameResult::truncated;
  out.src_addr = be32(&b[12]);
  out.dst_addr = be32(&b[16]);
  out.src_port = be16(u);
  out.dst_port = be16(u + 2);
  out.payload = b.subspan(udp_at + 8, ulen - 8);
  return FrameResult::udp;
}

// After the link header: skip VLAN tags, then IPv4.
FrameResult parse_ether_payload(uint16_t type, std::span<const uint8_t> b, UdpDatagram& out) {
  for (int tags = 0; (type == kEtherVlan || type == kEtherQinQ) && tags < 4; ++tags) {
    if (b.size() < 4) return FrameResult::truncated;
    type = be16(&b[2]);
    b = b.subspan(4);
  }
  if (type != kEtherIpv4) return FrameResult::not_ipv4;
  return parse_ipv4(b, out);
}
}  // namespace

FrameResult parse_udp_frame(int link_type, std::span<const uint8_t> f, UdpDatagram& out) {
  switch (link_type) {
    case link::kEthernet:
      if (f.size() < 14) return FrameResult::truncated;
      return parse_ether_payload(be16(&f[12]), f.subspan(14), out);
    case link::kLinuxSll:  // 16-byte header, protocol at 14
      if (f.size() < 16) return FrameResult::truncated;
      return parse_ether_payload(be16(&f[14]), f.subspan(16), out);
    case link::kLinuxSll2:  // 20-byte header, protocol at 0
      if (f.size() < 20) return FrameResult::truncated;
      return parse_ether_payload(be16(&f[0]), f.subspan(20), out);
    case link::kRaw:
    case link::kRawDlt:
    case link::kRawDlt14:
    case link::kIpv4:
      return parse_ipv4(f, out);
    case link::kNull:
    case link::kLoop: {  // 4-byte address family, host or network order; AF_INET = 2
      if (f.size() < 4) return FrameResult::truncated;
      const bool inet = (f[0] == 2 && f[1] == 0 && f[2] == 0 && f[3] == 0) ||
                        (f[0] == 0 && f[1] == 0 && f[2] == 0 && f[3] == 2);
      if (!inet) return FrameResult::not_ipv4;
      return parse_ipv4(f.subspan(4), out);
    }
    default:
      return FrameResult::unsupported_link;
  }
}

void FrameStats::count(FrameResult r) {
  ++frames;
  switch (r) {
    case FrameResult::udp:
      ++udp;
      break;
    case FrameResult::unsupported_link:
      ++unsupported_link;
      break;
    case FrameResult::not_ipv4:
      ++not_ipv4;
      break;
    case FrameResult::not_udp:
      ++not_udp;
      break;
    case FrameResult::ip_fragment:
      ++ip_fragments;
      break;
    case FrameResult::truncated:
      ++truncated;
      break;
    case FrameResult::malformed:
      ++malformed;
      break;
  }
}

}  // namespace storey::drivers::pcap
