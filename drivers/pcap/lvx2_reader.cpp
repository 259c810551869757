#include "drivers/pcap/lvx2_reader.hpp"

#include <cstring>
#include <fstream>

#include "drivers/lidar/mid360.hpp"

namespace storey::drivers::pcap {

namespace lidar = storey::drivers::lidar;

namespace {
template <class T>
bool read_at(std::span<const uint8_t> f, std::size_t at, T& v) {
  if (at > f.size() || f.size() - at < sizeof(T)) return false;
  std::memcpy(&v, f.data() + at, sizeof(T));
  return true;
}
}  // namespace

bool Lvx2Reader::fail(const std::string& what, std::size_t at) {
  error_ = "lvx2: " + what + " at byte " + std::to_string(at);
  return false;
}

bool Lvx2Reader::open(std::span<const uint8_t> file, std::string* error) {
  file_ = file;
  devices_.clear();
  error_.clear();
  in_frame_ = false;
  frames_ = 0;
  auto bad = [&](const std::string& what, std::size_t at) {
    fail(what, at);
    if (error != nullptr) *error = error_;
    return false;
  };
  Lvx2PublicHeader pub;
  if (!read_at(file, 0, pub)) return bad("file shorter than the public header", 0);
  if (std::strncmp(pub.signature, "livox_tech", 10) != 0) return bad("signature not livox_tech", 0);
  if (pub.magic != kLvx2Magic) return bad("magic code not 0xAC0EA767", 20);
  if (!read_at(file, sizeof(pub), priv_)) return bad("truncated private header", sizeof(pub));
  std::size_t at = sizeof(pub) + sizeof(priv_);
  for (int i = 0; i < priv_.device_count; ++i) {
    Lvx2DeviceInfo d;
    if (!read_at(file, at, d)) return bad("truncated device record " + std::to_string(i), at);
    devices_.push_back(d);
    at += sizeof(d);
  }
  frame_at_ = at;
  return true;
}

bool Lvx2Reader::next(Lvx2Package& out) {
  if (!error_.empty()) return false;
  for (;;) {
    if (!in_frame_) {
      if (frame_at_ >= file_.size()) return false;  // clean end
      Lvx2FrameHeader fh;
      if (!read_at(file_, frame_at_, fh)) return fail("truncated frame header", frame_at_);
      if (fh.current_offset != frame_at_) return fail("frame header offset mismatch", frame_at_);
      const std::size_t first = frame_at_ + sizeof(fh);
      // The last frame may say 0 or point past the end; packages then run to the end of file.
      std::size_t end = (fh.next_offset == 0 || fh.next_offset > file_.size())
                            ? file_.size()
                            : static_cast<std::size_t>(fh.next_offset);
      if (end < first) return fail("next frame offset before this frame's data", frame_at_);
      frame_index_ = fh.frame_index;
      pos_ = first;
      frame_end_ = end;
      in_frame_ = true;
      ++frames_;
    }
    if (pos_ >= frame_end_) {
      in_frame_ = false;
      frame_at_ = frame_end_;
      continue;
    }
    Lvx2PackageHeader ph;
    if (frame_end_ - pos_ < sizeof(ph) || !read_at(file_, pos_, ph)) {
      return fail("truncated package header", pos_);
    }
    const std::size_t data_at = pos_ + sizeof(ph);
    if (ph.length > frame_end_ - data_at) return fail("package longer than its frame", pos_);
    out.header = ph;
    out.data = file_.subspan(data_at, ph.length);
    out.frame_index = frame_index_;
    pos_ = data_at + ph.length;
    return true;
  }
}

std::size_t lvx2_to_sdk_packet(const Lvx2Package& pkg, uint16_t time_interval,
                               std::span<uint8_t> out) {
  const std::size_t item = lidar::mid360_item_size(pkg.header.data_type);
  if (item == 0 || pkg.data.size() % item != 0) return 0;
  const std::size_t len = lidar::kMid360HeaderSize + pkg.data.size();
  if (len > 65535 || out.size() < len || pkg.data.size() / item > 65535) return 0;
  lidar::Mid360Header h{};
  h.version = 0;
  h.length = static_cast<uint16_t>(len);
  h.time_interval = time_interval;
  h.dot_num = static_cast<uint16_t>(pkg.data.size() / item);
  h.udp_cnt = pkg.header.udp_counter;
  h.frame_cnt = pkg.header.frame_counter;
  h.data_type = pkg.header.data_type;
  h.time_type = pkg.header.timestamp_type;
  h.crc32 = 0;
  h.timestamp = pkg.header.timestamp;
  std::memcpy(out.data(), &h, sizeof(h));
  if (!pkg.data.empty()) std::memcpy(out.data() + sizeof(h), pkg.data.data(), pkg.data.size());
  return len;
}

// ---- writer ----

namespace {
template <class T>
void append(std::vector<uint8_t>& v, const T& x) {
  const auto* p = reinterpret_cast<const uint8_t*>(&x);
  v.insert(v.end(), p, p + sizeof(T));
}
}  // namespace

Lvx2Writer::Lvx2Writer(std::vector<uint8_t>& out, uint32_t frame_duration_ms)
    : out_(out), frame_duration_ms_(frame_duration_ms) {}

void Lvx2Writer::add_device(const Lvx2DeviceInfo& d) {
  devices_.push_back(d);
}

void Lvx2Writer::finish_headers() {
  if (headers_done_) return;
  Lvx2PublicHeader pub{};
  std::memcpy(pub.signature, "livox_tech", 10);
  pub.version[0] = 2;
  pub.magic = kLvx2Magic;
  append(out_, pub);
  Lvx2PrivateHeader priv{frame_duration_ms_, static_cast<uint8_t>(devices_.size())};
  append(out_, priv);
  for (const auto& d : devices_) append(out_, d);
  headers_done_ = true;
}

void Lvx2Writer::begin_frame() {
  finish_headers();
  frame_at_ = out_.size();
  Lvx2FrameHeader fh{frame_at_, 0, frame_index_++};
  append(out_, fh);
}

bool Lvx2Writer::add_sdk_packet(std::span<const uint8_t> pkt, uint32_t lidar_id) {
  lidar::Mid360Header h;
  if (lidar::mid360_validate(pkt, h) != lidar::DropReason::none || h.data_type == 0) return false;
  Lvx2PackageHeader ph{};
  ph.version = 0;
  ph.lidar_id = lidar_id;
  ph.lidar_type = 8;
  ph.timestamp_type = h.time_type;
  ph.timestamp = h.timestamp;
  ph.udp_counter = h.udp_cnt;
  ph.data_type = h.data_type;
  ph.length = static_cast<uint32_t>(pkt.size() - lidar::kMid360HeaderSize);
  ph.frame_counter = h.frame_cnt;
  append(out_, ph);
  out_.insert(out_.end(), pkt.begin() + lidar::kMid360HeaderSize, pkt.end());
  return true;
}

void Lvx2Writer::end_frame() {
  const uint64_t next = out_.size();
  std::memcpy(out_.data() + frame_at_ + offsetof(Lvx2FrameHeader, next_offset), &next,
              sizeof(next));
}

bool load_file(const std::string& path, std::vector<uint8_t>& out, std::string* error) {
  std::ifstream f(path, std::ios::binary | std::ios::ate);
  if (!f) {
    if (error != nullptr) *error = path + ": cannot open";
    return false;
  }
  const auto size = f.tellg();
  out.resize(static_cast<std::size_t>(size));
  f.seekg(0);
  if (!f.read(reinterpret_cast<char*>(out.data()), size)) {
    if (error != nullptr) *error = path + ": read error";
    return false;
  }
  return true;
}

}  // namespace storey::drivers::pcap
