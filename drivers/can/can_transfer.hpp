// Multi-frame transfers: a message body longer than one CAN frame is split into consecutive
// frames on one CAN id, each starting with a control byte, and protected end to end by a CRC-32.
//   transfer = body | CRC-32 (zlib) of body, u32 little endian
//   frame i  = data[0] control: bits 7..5 transfer counter (0..7), bits 4..0 frame index i
//              data[1..] the next chunk of the transfer (7 bytes classic, 63 bytes FD)
// The receiver knows the transfer length from the id (fixed-size messages), so no length field;
// the counter keeps frames of consecutive transfers from being mixed after a loss.
// Dependency-free (std + drivers/crc.hpp): compiled standalone by the fuzz target.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "drivers/can/can_frame.hpp"

namespace storey::drivers::can {

inline constexpr size_t kClassicChunk = 7;
inline constexpr size_t kFdChunk = 63;
inline constexpr size_t kMaxFramesPerTransfer = 32;
inline constexpr size_t kMaxTransferSize = 256;  // body + CRC

// Frames needed for a body of `body_len` bytes (+4 CRC).
size_t transfer_frame_count(size_t body_len, bool fd);

// Splits body + CRC into frames on `id`. Returns the number of frames written to `out`
// (capacity `max_frames`), 0 if it does not fit.
size_t encode_transfer(uint32_t id, const uint8_t* body, size_t body_len, uint8_t counter, bool fd,
                       CanFrame* out, size_t max_frames);

// Reassembles transfers for up to kStreams ids. Each id must be registered with its body size.
class CanReassembler {
 public:
  static constexpr size_t kStreams = 8;

  enum class Result : uint8_t {
    complete,     // `body()`/`body_len()` hold a verified transfer body
    in_progress,  // frame accepted, more to come
    unknown_id,   // not a registered id (filters should have stopped it)
    bad_frame,    // wrong length/kind, index out of order, counter mismatch: transfer dropped
    bad_crc,      // complete but CRC mismatch: transfer dropped
  };

  // Registers an id (with flags as sent) whose transfers carry body_len bytes. False if full or
  // body too long.
  bool add_stream(uint32_t id, size_t body_len);
  Result push(const CanFrame& f);

  const uint8_t* body() const { return body_; }
  size_t body_len() const { return body_len_; }
  uint32_t last_id() const { return last_id_; }
  uint64_t incomplete_transfers() const { return incomplete_; }

 private:
  struct Stream {
    uint32_t id = 0;
    size_t body_len = 0;
    size_t received = 0;  // transfer bytes received so far
    uint8_t next_index = 0;
    uint8_t counter = 0;
    bool active = false;
    std::array<uint8_t, kMaxTransferSize> buf{};
  };
  std::array<Stream, kStreams> streams_{};
  size_t n_streams_ = 0;
  const uint8_t* body_ = nullptr;
  size_t body_len_ = 0;
  uint32_t last_id_ = 0;
  uint64_t incomplete_ = 0;
};

}  // namespace storey::drivers::can
