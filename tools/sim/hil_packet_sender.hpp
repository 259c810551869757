// UDP sender of simulated sensor datagrams for hardware-in-the-loop: one socket bound to the
// sensor's source address (so the firmware's source filter accepts it), datagrams queued during
// a loop step and sent together with one sendmmsg call. Storage is fixed at open(); queue() and
// flush() never allocate. Used by the HIL loop thread only.
#pragma once

#include <netinet/in.h>
#include <sys/socket.h>

#include <cstdint>
#include <span>
#include <string>
#include <vector>

struct mmsghdr;

namespace storey::tools::sim {

class HilPacketSender {
 public:
  struct Options {
    std::string source_address = "127.0.0.1";  // must be an address of this machine
    uint16_t source_port = 0;                  // 0 = ephemeral; see fallback below
    std::string dest_address = "127.0.0.1";
    uint16_t dest_port = 0;
    std::size_t max_datagram = 1500;
    std::size_t batch = 64;  // datagrams per flush
    int send_buffer_bytes = 4 << 20;
  };
  struct Counters {
    uint64_t sent = 0;         // datagrams the kernel accepted
    uint64_t send_errors = 0;  // refused (buffer full, no listener errors, ...)
    uint64_t overflow = 0;     // queued beyond `batch` before a flush: dropped, counted
    uint64_t bytes = 0;
  };

  HilPacketSender() = default;
  ~HilPacketSender();
  HilPacketSender(const HilPacketSender&) = delete;
  HilPacketSender& operator=(const HilPacketSender&) = delete;

  // Opens and binds the socket. Returns "" on success or a one-line reason naming the address.
  // A source port already in use falls back to an ephemeral one (the firmware filters on the
  // address only) and leaves a note in warning().
  std::string open(const Options& options);
  bool is_open() const { return fd_ >= 0; }
  const std::string& warning() const { return warning_; }
  uint16_t bound_port() const { return bound_port_; }

  // Copies one datagram into the batch (false and counted when the batch is full or too long).
  bool queue(std::span<const uint8_t> datagram);
  // Sends everything queued; returns datagrams sent.
  int flush();
  const Counters& counters() const { return counters_; }

 private:
  int fd_ = -1;
  Options opt_;
  std::string warning_;
  uint16_t bound_port_ = 0;
  sockaddr_in dest_{};
  std::vector<uint8_t> buffers_;
  std::vector<uint16_t> sizes_;
  std::vector<struct iovec> iovs_;
  std::vector<::mmsghdr> msgs_;
  std::size_t pending_ = 0;
  Counters counters_;
};

}  // namespace storey::tools::sim
