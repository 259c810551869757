#include "drivers/pcap/pcap_reader.hpp"

#include <pcap/pcap.h>

#include <cstring>

namespace storey::drivers::pcap {

PcapReader::~PcapReader() {
  close();
}

void PcapReader::close() {
  if (handle_ != nullptr) pcap_close(handle_);
  handle_ = nullptr;
}

bool PcapReader::open(const std::string& path, std::string* error) {
  close();
  path_ = path;
  stats_ = FrameStats{};
  error_.clear();
  char err[PCAP_ERRBUF_SIZE] = {0};
  // Handles both pcap and pcapng; timestamps delivered in ns whatever the file holds.
  handle_ = pcap_open_offline_with_tstamp_precision(path.c_str(), PCAP_TSTAMP_PRECISION_NANO, err);
  if (handle_ == nullptr) {
    error_ = path + ": cannot open capture: " + err;
    if (error != nullptr) *error = error_;
    return false;
  }
  link_type_ = pcap_datalink(handle_);
  return true;
}

void PcapReader::add_port(uint16_t port) {
  if (n_ports_ < static_cast<int>(ports_.size())) ports_[n_ports_++] = port;
}

bool PcapReader::next(UdpDatagram& out) {
  if (handle_ == nullptr) return false;
  for (;;) {
    pcap_pkthdr* hdr = nullptr;
    const u_char* data = nullptr;
    const int rc = pcap_next_ex(handle_, &hdr, &data);
    if (rc == PCAP_ERROR_BREAK) return false;  // end of file
    if (rc != 1) {
      error_ = path_ + ": read error: " + pcap_geterr(handle_);
      return false;
    }
    const FrameResult r =
        parse_udp_frame(link_type_, std::span<const uint8_t>(data, hdr->caplen), out);
    stats_.count(r);
    if (r != FrameResult::udp) continue;
    if (out.ip_length_mismatch) ++stats_.ip_length_mismatch;
    if (n_ports_ > 0) {
      bool keep = false;
      for (int i = 0; i < n_ports_; ++i) {
        keep |= out.dst_port == ports_[i] || out.src_port == ports_[i];
      }
      if (!keep) {
        ++stats_.port_filtered;
        continue;
      }
    }
    out.timestamp_ns = static_cast<uint64_t>(hdr->ts.tv_sec) * 1000000000ull +
                       static_cast<uint64_t>(hdr->ts.tv_usec);
    return true;
  }
}

// ---- writer ----

PcapWriter::~PcapWriter() {
  close();
}

bool PcapWriter::open(const std::string& path, std::string* error) {
  close();
  dead_ = pcap_open_dead_with_tstamp_precision(DLT_EN10MB, 65535, PCAP_TSTAMP_PRECISION_NANO);
  if (dead_ == nullptr) {
    if (error != nullptr) *error = path + ": pcap_open_dead failed";
    return false;
  }
  dumper_ = pcap_dump_open(dead_, path.c_str());
  if (dumper_ == nullptr) {
    if (error != nullptr) *error = path + ": cannot write capture: " + pcap_geterr(dead_);
    pcap_close(dead_);
    dead_ = nullptr;
    return false;
  }
  return true;
}

namespace {
void put16(uint8_t* p, uint16_t v) {
  p[0] = static_cast<uint8_t>(v >> 8);
  p[1] = static_cast<uint8_t>(v);
}
void put32(uint8_t* p, uint32_t v) {
  put16(p, static_cast<uint16_t>(v >> 16));
  put16(p + 2, static_cast<uint16_t>(v));
}
}  // namespace

bool PcapWriter::write(const UdpDatagram& d) {
  if (dumper_ == nullptr) return false;
  const std::size_t n = d.payload.size();
  if (n > 65507) return false;
  uint8_t* f = frame_.data();
  // Ethernet: locally administered MACs derived from nothing in particular, type IPv4.
  const uint8_t dst_mac[6] = {0x02, 0, 0, 0, 0, 0x01}, src_mac[6] = {0x02, 0, 0, 0, 0, 0x02};
  std::memcpy(f, dst_mac, 6);
  std::memcpy(f + 6, src_mac, 6);
  put16(f + 12, 0x0800);
  uint8_t* ip = f + 14;
  ip[0] = 0x45;
  ip[1] = 0;
  put16(ip + 2, static_cast<uint16_t>(20 + 8 + n));
  put16(ip + 4, ip_id_++);
  put16(ip + 6, 0x4000);  // don't fragment
  ip[8] = 64;
  ip[9] = 17;
  put16(ip + 10, 0);
  put32(ip + 12, d.src_addr);
  put32(ip + 16, d.dst_addr);
  uint32_t sum = 0;
  for (int i = 0; i < 20; i += 2) sum += (ip[i] << 8) | ip[i + 1];
  while (sum >> 16) sum = (sum & 0xFFFF) + (sum >> 16);
  put16(ip + 10, static_cast<uint16_t>(~sum));
  uint8_t* udp = ip + 20;
  put16(udp, d.src_port);
  put16(udp + 2, d.dst_port);
  put16(udp + 4, static_cast<uint16_t>(8 + n));
  put16(udp + 6, 0);  // checksum optional in IPv4
  if (n > 0) std::memcpy(udp + 8, d.payload.data(), n);
  pcap_pkthdr h{};
  h.ts.tv_sec = static_cast<time_t>(d.timestamp_ns / 1000000000ull);
  h.ts.tv_usec = static_cast<suseconds_t>(d.timestamp_ns % 1000000000ull);  // ns (NANO precision)
  h.caplen = h.len = static_cast<bpf_u_int32>(14 + 20 + 8 + n);
  pcap_dump(static_cast<u_char*>(dumper_), &h, f);
  ++written_;
  return true;
}

void PcapWriter::flush() {
  if (dumper_ != nullptr) pcap_dump_flush(static_cast<pcap_dumper_t*>(dumper_));
}

void PcapWriter::close() {
  if (dumper_ != nullptr) pcap_dump_close(static_cast<pcap_dumper_t*>(dumper_));
  dumper_ = nullptr;
  if (dead_ != nullptr) pcap_close(dead_);
  dead_ = nullptr;
}

}  // namespace storey::drivers::pcap
