#include "drivers/can/can_transfer.hpp"

#include <algorithm>
#include <cstring>

#include "drivers/crc.hpp"

namespace storey::drivers::can {

using storey::drivers::crc32_zlib;

size_t transfer_frame_count(size_t body_len, bool fd) {
  const size_t chunk = fd ? kFdChunk : kClassicChunk;
  return (body_len + 4 + chunk - 1) / chunk;
}

size_t encode_transfer(uint32_t id, const uint8_t* body, size_t body_len, uint8_t counter, bool fd,
                       CanFrame* out, size_t max_frames) {
  const size_t total = body_len + 4;
  const size_t frames = transfer_frame_count(body_len, fd);
  if (total > kMaxTransferSize || frames > kMaxFramesPerTransfer || frames > max_frames) return 0;
  uint8_t buf[kMaxTransferSize];
  std::memcpy(buf, body, body_len);
  const uint32_t crc = crc32_zlib({body, body_len});
  for (int i = 0; i < 4; ++i) buf[body_len + i] = static_cast<uint8_t>(crc >> (8 * i));
  const size_t chunk = fd ? kFdChunk : kClassicChunk;
  for (size_t i = 0; i < frames; ++i) {
    CanFrame& f = out[i];
    f = CanFrame{};
    f.id = id;
    f.fd = fd;
    f.flags = fd ? kCanFdBrs : 0;
    const size_t off = i * chunk;
    const size_t n = std::min(chunk, total - off);
    f.data[0] = static_cast<uint8_t>(((counter & 0x7u) << 5) | (i & 0x1Fu));
    std::memcpy(f.data.data() + 1, buf + off, n);
    f.len = static_cast<uint8_t>(fd ? canfd_round_len(n + 1) : n + 1);
  }
  return frames;
}

bool CanReassembler::add_stream(uint32_t id, size_t body_len) {
  // Classic frames bound the transfer: 32 frames x 7 bytes.
  if (n_streams_ >= kStreams || body_len + 4 > kClassicChunk * kMaxFramesPerTransfer) return false;
  Stream& s = streams_[n_streams_++];
  s = Stream{};
  s.id = id;
  s.body_len = body_len;
  return true;
}

CanReassembler::Result CanReassembler::push(const CanFrame& f) {
  Stream* s = nullptr;
  for (size_t i = 0; i < n_streams_; ++i) {
    if (streams_[i].id == f.id) s = &streams_[i];
  }
  if (s == nullptr) return Result::unknown_id;
  last_id_ = f.id;
  if (f.len < 1) {
    if (s->active) ++incomplete_;
    s->active = false;
    return Result::bad_frame;
  }
  const uint8_t index = f.data[0] & 0x1Fu;
  const uint8_t counter = f.data[0] >> 5;
  if (index == 0) {
    if (s->active) ++incomplete_;  // the previous transfer lost its tail
    s->active = true;
    s->received = 0;
    s->next_index = 0;
    s->counter = counter;
  }
  if (!s->active || index != s->next_index || counter != s->counter) {
    if (s->active) ++incomplete_;
    s->active = false;
    return Result::bad_frame;
  }
  const size_t total = s->body_len + 4;
  const size_t chunk = f.fd ? kFdChunk : kClassicChunk;
  const size_t n = std::min(chunk, total - s->received);
  // Classic frames carry exactly 1 + n bytes; FD frames the padded size of that.
  const size_t want_len = f.fd ? canfd_round_len(n + 1) : n + 1;
  if (f.len != want_len) {
    ++incomplete_;
    s->active = false;
    return Result::bad_frame;
  }
  std::memcpy(s->buf.data() + s->received, f.data.data() + 1, n);
  s->received += n;
  ++s->next_index;
  if (s->received < total) return Result::in_progress;
  s->active = false;
  uint32_t got = 0;
  for (int i = 0; i < 4; ++i) got |= static_cast<uint32_t>(s->buf[s->body_len + i]) << (8 * i);
  if (crc32_zlib({s->buf.data(), s->body_len}) != got) return Result::bad_crc;
  body_ = s->buf.data();
  body_len_ = s->body_len;
  return Result::complete;
}

}  // namespace storey::drivers::can
