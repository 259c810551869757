// Minimal non-blocking UDP socket (IPv4) used by the CAN-over-UDP transport and the Go2 UDP
// link. Setup calls return false with error() set; send/receive never block.
#pragma once

#include <netinet/in.h>

#include <cstddef>
#include <cstdint>
#include <string>

namespace storey::drivers::can {

struct UdpEndpoint {
  std::string address = "127.0.0.1";
  uint16_t port = 0;
};

class UdpSocket {
 public:
  UdpSocket() = default;
  ~UdpSocket();
  UdpSocket(const UdpSocket&) = delete;
  UdpSocket& operator=(const UdpSocket&) = delete;

  // Binds to `local` (port 0: ephemeral). If `remote.port` is 0, datagrams go to the sender of
  // the last datagram the caller validated with adopt_last_sender() (the robot side learns its
  // peer this way, and garbage from elsewhere cannot redirect it).
  bool open(const UdpEndpoint& local, const UdpEndpoint& remote, int rcvbuf_bytes = 1 << 20);
  bool is_open() const { return fd_ >= 0; }
  const std::string& error() const { return error_; }
  uint16_t local_port() const;

  enum class Io : uint8_t { ok, empty, would_block, no_peer, error };
  Io send(const uint8_t* data, size_t len);
  // Receives one datagram into buf; `len` set to its size (truncated datagrams are reported as
  // size cap+1 so that callers reject them).
  Io receive(uint8_t* buf, size_t cap, size_t& len);
  void adopt_last_sender();

 private:
  int fd_ = -1;
  sockaddr_in peer_{};
  sockaddr_in last_from_{};
  bool have_peer_ = false;
  bool learn_peer_ = false;
  std::string error_;
};

}  // namespace storey::drivers::can
