#include "tools/sim/hil_packet_sender.hpp"

#include <arpa/inet.h>
#include <sys/uio.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace storey::tools::sim {

HilPacketSender::~HilPacketSender() {
  if (fd_ >= 0) ::close(fd_);
}

std::string HilPacketSender::open(const Options& options) {
  opt_ = options;
  if (opt_.batch == 0 || opt_.max_datagram == 0) return "packet sender: batch and size must be > 0";
  sockaddr_in src{};
  src.sin_family = AF_INET;
  if (::inet_pton(AF_INET, opt_.source_address.c_str(), &src.sin_addr) != 1)
    return "source address '" + opt_.source_address + "' is not an IPv4 address";
  dest_ = {};
  dest_.sin_family = AF_INET;
  dest_.sin_port = htons(opt_.dest_port);
  if (::inet_pton(AF_INET, opt_.dest_address.c_str(), &dest_.sin_addr) != 1)
    return "destination address '" + opt_.dest_address + "' is not an IPv4 address";
  if (opt_.dest_port == 0) return "destination port 0 for " + opt_.dest_address;
  fd_ = ::socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd_ < 0) return std::string("socket(): ") + std::strerror(errno);
  ::setsockopt(fd_, SOL_SOCKET, SO_SNDBUF, &opt_.send_buffer_bytes, sizeof(int));
  // No SO_REUSEADDR: sharing a port with the firmware's receiving socket could steal its packets.
  src.sin_port = htons(opt_.source_port);
  if (::bind(fd_, reinterpret_cast<sockaddr*>(&src), sizeof(src)) != 0) {
    const int e = errno;
    if (e == EADDRINUSE && opt_.source_port != 0) {
      warning_ = "source port " + std::to_string(opt_.source_port) + " on " + opt_.source_address +
                 " is in use; sending from an ephemeral port";
      src.sin_port = 0;
      if (::bind(fd_, reinterpret_cast<sockaddr*>(&src), sizeof(src)) != 0) {
        const std::string why = std::strerror(errno);
        ::close(fd_);
        fd_ = -1;
        return "bind " + opt_.source_address + ": " + why;
      }
    } else {
      ::close(fd_);
      fd_ = -1;
      std::string why = "bind " + opt_.source_address + ":" + std::to_string(opt_.source_port) +
                        ": " + std::strerror(e);
      if (e == EADDRNOTAVAIL)
        why += " (not an address of this machine; for HIL use 127.0.0.x, see config/hil.yaml)";
      return why;
    }
  }
  sockaddr_in bound{};
  socklen_t len = sizeof(bound);
  ::getsockname(fd_, reinterpret_cast<sockaddr*>(&bound), &len);
  bound_port_ = ntohs(bound.sin_port);
  buffers_.assign(opt_.batch * opt_.max_datagram, 0);
  sizes_.assign(opt_.batch, 0);
  iovs_.resize(opt_.batch);
  msgs_.resize(opt_.batch);
  pending_ = 0;
  return "";
}

bool HilPacketSender::queue(std::span<const uint8_t> datagram) {
  if (fd_ < 0 || pending_ >= opt_.batch || datagram.size() > opt_.max_datagram) {
    ++counters_.overflow;
    return false;
  }
  std::memcpy(buffers_.data() + pending_ * opt_.max_datagram, datagram.data(), datagram.size());
  sizes_[pending_] = static_cast<uint16_t>(datagram.size());
  ++pending_;
  return true;
}

int HilPacketSender::flush() {
  if (fd_ < 0 || pending_ == 0) return 0;
  for (std::size_t i = 0; i < pending_; ++i) {
    iovs_[i].iov_base = buffers_.data() + i * opt_.max_datagram;
    iovs_[i].iov_len = sizes_[i];
    msgs_[i] = {};
    msgs_[i].msg_hdr.msg_name = &dest_;
    msgs_[i].msg_hdr.msg_namelen = sizeof(dest_);
    msgs_[i].msg_hdr.msg_iov = &iovs_[i];
    msgs_[i].msg_hdr.msg_iovlen = 1;
  }
  std::size_t done = 0, sent = 0;
  while (done < pending_) {
    const int n = ::sendmmsg(fd_, msgs_.data() + done, static_cast<unsigned>(pending_ - done), 0);
    if (n > 0) {
      for (int i = 0; i < n; ++i) counters_.bytes += sizes_[done + i];
      done += static_cast<std::size_t>(n);
      sent += static_cast<std::size_t>(n);
      counters_.sent += static_cast<uint64_t>(n);
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    // EAGAIN (buffer full) or ECONNREFUSED (an earlier datagram found no listener): skip the
    // datagram that failed, count it, carry on with the rest.
    ++counters_.send_errors;
    ++done;
  }
  pending_ = 0;
  return static_cast<int>(sent);
}

}  // namespace storey::tools::sim
