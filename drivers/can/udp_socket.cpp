#include "drivers/can/udp_socket.hpp"

#include <arpa/inet.h>
#include <errno.h>
#include <fcntl.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

namespace storey::drivers::can {
namespace {
bool to_sockaddr(const UdpEndpoint& e, sockaddr_in& out) {
  out = sockaddr_in{};
  out.sin_family = AF_INET;
  out.sin_port = htons(e.port);
  return inet_pton(AF_INET, e.address.c_str(), &out.sin_addr) == 1;
}
}  // namespace

UdpSocket::~UdpSocket() {
  if (fd_ >= 0) ::close(fd_);
}

bool UdpSocket::open(const UdpEndpoint& local, const UdpEndpoint& remote, int rcvbuf_bytes) {
  sockaddr_in la{};
  if (!to_sockaddr(local, la)) {
    error_ = "bad local address '" + local.address + "'";
    return false;
  }
  learn_peer_ = remote.port == 0;
  if (!learn_peer_) {
    if (!to_sockaddr(remote, peer_)) {
      error_ = "bad remote address '" + remote.address + "'";
      return false;
    }
    have_peer_ = true;
  }
  fd_ = ::socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd_ < 0) {
    error_ = std::string("socket(AF_INET, SOCK_DGRAM): ") + strerror(errno);
    return false;
  }
  // Best effort: a larger buffer rides out scheduling hiccups; the kernel clamps to rmem_max.
  ::setsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &rcvbuf_bytes, sizeof(rcvbuf_bytes));
  if (::bind(fd_, reinterpret_cast<sockaddr*>(&la), sizeof(la)) != 0) {
    error_ = "bind " + local.address + ":" + std::to_string(local.port) + ": " + strerror(errno);
    ::close(fd_);
    fd_ = -1;
    return false;
  }
  return true;
}

uint16_t UdpSocket::local_port() const {
  sockaddr_in a{};
  socklen_t n = sizeof(a);
  if (fd_ < 0 || ::getsockname(fd_, reinterpret_cast<sockaddr*>(&a), &n) != 0) return 0;
  return ntohs(a.sin_port);
}

UdpSocket::Io UdpSocket::send(const uint8_t* data, size_t len) {
  if (fd_ < 0) return Io::error;
  if (!have_peer_) return Io::no_peer;
  const ssize_t r =
      ::sendto(fd_, data, len, MSG_DONTWAIT, reinterpret_cast<sockaddr*>(&peer_), sizeof(peer_));
  if (r == static_cast<ssize_t>(len)) return Io::ok;
  if (r < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) return Io::would_block;
  // ECONNREFUSED (ICMP port unreachable from an earlier send) is transient on UDP.
  return Io::error;
}

UdpSocket::Io UdpSocket::receive(uint8_t* buf, size_t cap, size_t& len) {
  if (fd_ < 0) return Io::error;
  sockaddr_in from{};
  socklen_t fl = sizeof(from);
  for (;;) {
    const ssize_t r = ::recvfrom(fd_, buf, cap, MSG_DONTWAIT | MSG_TRUNC,
                                 reinterpret_cast<sockaddr*>(&from), &fl);
    if (r >= 0) {
      len = static_cast<size_t>(r) > cap ? cap + 1 : static_cast<size_t>(r);
      last_from_ = from;
      return Io::ok;
    }
    if (errno == EAGAIN || errno == EWOULDBLOCK) return Io::empty;
    if (errno == EINTR || errno == ECONNREFUSED) continue;  // ICMP error from an earlier send
    return Io::error;
  }
}

void UdpSocket::adopt_last_sender() {
  if (!learn_peer_ || last_from_.sin_family != AF_INET) return;
  peer_ = last_from_;
  have_peer_ = true;
}

}  // namespace storey::drivers::can
