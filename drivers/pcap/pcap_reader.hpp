#pragma once
// Reads UDP datagrams from pcap and pcapng captures (tcpdump, Wireshark, our PcapWriter) through
// libpcap, filtered by UDP port. Runs on a non-RT thread (replay loop or tools): it does file I/O.
#include <array>
#include <cstdint>
#include <string>

#include "drivers/pcap/udp_frame.hpp"

struct pcap;  // libpcap's handle (pcap_t)

namespace storey::drivers::pcap {

class PcapReader {
 public:
  PcapReader() = default;
  ~PcapReader();
  PcapReader(const PcapReader&) = delete;
  PcapReader& operator=(const PcapReader&) = delete;

  // Opens a pcap or pcapng file; false with a one-line reason naming the file otherwise.
  bool open(const std::string& path, std::string* error);
  void close();

  // Keeps only datagrams whose destination or source port is one of `ports` (up to 8; none set =
  // keep every UDP datagram). Both ends are matched because sensors differ: the VLP-16 sends
  // 2368 -> 2368, the Mid-360 56300 -> 56301.
  void add_port(uint16_t port);

  // Next matching datagram in capture order; false at the end of the file (or on a read error,
  // see error()). The payload stays valid until the next call.
  bool next(UdpDatagram& out);

  int link_type() const { return link_type_; }
  const FrameStats& stats() const { return stats_; }
  const std::string& error() const { return error_; }

 private:
  ::pcap* handle_ = nullptr;
  int link_type_ = -1;
  std::array<uint16_t, 8> ports_{};
  int n_ports_ = 0;
  FrameStats stats_;
  std::string error_;
  std::string path_;
};

// Writes UDP datagrams as an Ethernet/IPv4/UDP pcap (nanosecond timestamps) readable by
// tcpdump, Wireshark and PcapReader. Used by `storey run --record`; it does file I/O, so it
// belongs on a non-RT thread fed by a queue.
class PcapWriter {
 public:
  PcapWriter() = default;
  ~PcapWriter();
  PcapWriter(const PcapWriter&) = delete;
  PcapWriter& operator=(const PcapWriter&) = delete;

  bool open(const std::string& path, std::string* error);
  // Addresses in host byte order. False if the payload does not fit one IPv4 datagram.
  bool write(const UdpDatagram& d);
  void flush();
  void close();
  uint64_t written() const { return written_; }

 private:
  ::pcap* dead_ = nullptr;
  void* dumper_ = nullptr;  // pcap_dumper_t
  uint16_t ip_id_ = 0;
  uint64_t written_ = 0;
  std::array<uint8_t, 14 + 20 + 8 + 65507> frame_{};
};

}  // namespace storey::drivers::pcap
