// libFuzzer target: capture files (pcap/pcapng, parsed by libpcap from memory) and our link-layer
// / IPv4 / UDP parsing of every frame; also the raw frame parser on the input for each link type.
#include <pcap/pcap.h>

#include <cstdint>
#include <cstdio>

#include "drivers/pcap/udp_frame.hpp"

using namespace storey::drivers::pcap;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::span<const uint8_t> in(data, size);
  UdpDatagram d;
  for (int lt : {link::kEthernet, link::kLinuxSll, link::kLinuxSll2, link::kRaw, link::kNull}) {
    if (parse_udp_frame(lt, in, d) == FrameResult::udp) {
      if (d.payload.data() < data || d.payload.data() + d.payload.size() > data + size) {
        __builtin_trap();
      }
    }
  }
  std::FILE* f = fmemopen(const_cast<uint8_t*>(data), size, "rb");
  if (f == nullptr) return 0;
  char err[PCAP_ERRBUF_SIZE];
  pcap_t* p = pcap_fopen_offline_with_tstamp_precision(f, PCAP_TSTAMP_PRECISION_NANO, err);
  if (p == nullptr) {  // libpcap takes ownership of f only on success
    std::fclose(f);
    return 0;
  }
  const int lt = pcap_datalink(p);
  pcap_pkthdr* h;
  const u_char* frame;
  for (int i = 0; i < 10000 && pcap_next_ex(p, &h, &frame) == 1; ++i) {
    parse_udp_frame(lt, std::span<const uint8_t>(frame, h->caplen), d);
  }
  pcap_close(p);  // also closes f
  return 0;
}
