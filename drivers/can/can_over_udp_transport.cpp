#include "drivers/can/can_over_udp_transport.hpp"

namespace storey::drivers::can {

CanOverUdpTransport::CanOverUdpTransport(const UdpEndpoint& local, const UdpEndpoint& remote) {
  socket_.open(local, remote);
}

bool CanOverUdpTransport::set_filters(const CanFilter* filters, int n) {
  if (n < 0 || n > kMaxFilters) return false;
  for (int i = 0; i < n; ++i) filters_[i] = filters[i];
  n_filters_ = n;
  return true;
}

bool CanOverUdpTransport::passes(uint32_t id) const {
  if (n_filters_ == 0) return true;
  for (int i = 0; i < n_filters_; ++i) {
    if ((id & filters_[i].mask) == (filters_[i].id & filters_[i].mask)) return true;
  }
  return false;
}

CanIoStatus CanOverUdpTransport::send(const CanFrame& f) {
  uint8_t buf[kCanFdDatagram];
  const size_t n = encode_can_datagram(f, buf);
  switch (socket_.send(buf, n)) {
    case UdpSocket::Io::ok:
      ++stats_.frames_sent;
      return CanIoStatus::ok;
    case UdpSocket::Io::would_block:
      ++stats_.send_errors;
      return CanIoStatus::would_block;
    default:
      ++stats_.send_errors;
      return CanIoStatus::error;
  }
}

CanIoStatus CanOverUdpTransport::receive(CanFrame& f) {
  uint8_t buf[kCanFdDatagram + 1];
  for (;;) {
    size_t n = 0;
    const UdpSocket::Io r = socket_.receive(buf, kCanFdDatagram, n);
    if (r == UdpSocket::Io::empty) return CanIoStatus::empty;
    if (r != UdpSocket::Io::ok) return CanIoStatus::error;
    if (decode_can_datagram(buf, n, f) != CanDatagramError::ok) {
      ++stats_.malformed;
      return CanIoStatus::malformed;
    }
    if (!passes(f.id)) continue;  // filtered, as the kernel would
    socket_.adopt_last_sender();
    ++stats_.frames_received;
    return CanIoStatus::ok;
  }
}

}  // namespace storey::drivers::can
