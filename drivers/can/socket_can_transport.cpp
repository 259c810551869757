#include "drivers/can/socket_can_transport.hpp"

#include <errno.h>
#include <linux/can.h>
#include <linux/can/error.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <string.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include <cstring>

namespace storey::drivers::can {

static_assert(sizeof(struct can_frame) == kCanClassicDatagram, "struct can_frame layout");
static_assert(sizeof(struct canfd_frame) == kCanFdDatagram, "struct canfd_frame layout");

SocketCanTransport::SocketCanTransport(const SocketCanOptions& options) : options_(options) {
  open_socket();
}

SocketCanTransport::~SocketCanTransport() {
  close_socket();
}

int64_t SocketCanTransport::now_ns() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

void SocketCanTransport::close_socket() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

bool SocketCanTransport::open_socket() {
  const int fd = ::socket(AF_CAN, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC, CAN_RAW);
  if (fd < 0) {
    errno_ = errno;
    error_ = std::string("socket(AF_CAN, SOCK_RAW, CAN_RAW): ") + strerror(errno_) +
             (errno_ == EAFNOSUPPORT ? " (kernel without CAN support)" : "");
    return false;
  }
  auto fail = [&](const char* what) {
    errno_ = errno;
    error_ = std::string(what) + " on " + options_.interface + ": " + strerror(errno_);
    ::close(fd);
    return false;
  };
  const unsigned idx = if_nametoindex(options_.interface.c_str());
  if (idx == 0) return fail("if_nametoindex");
  const int one = 1;
  if (options_.fd_frames &&
      ::setsockopt(fd, SOL_CAN_RAW, CAN_RAW_FD_FRAMES, &one, sizeof(one)) != 0) {
    return fail("setsockopt(CAN_RAW_FD_FRAMES)");
  }
  // Error frames we act on: bus-off and controller restart, plus the counted rest.
  const can_err_mask_t err_mask = CAN_ERR_TX_TIMEOUT | CAN_ERR_LOSTARB | CAN_ERR_CRTL |
                                  CAN_ERR_PROT | CAN_ERR_TRX | CAN_ERR_ACK | CAN_ERR_BUSOFF |
                                  CAN_ERR_BUSERROR | CAN_ERR_RESTARTED;
  if (::setsockopt(fd, SOL_CAN_RAW, CAN_RAW_ERR_FILTER, &err_mask, sizeof(err_mask)) != 0) {
    return fail("setsockopt(CAN_RAW_ERR_FILTER)");
  }
  const int own = options_.receive_own ? 1 : 0;
  ::setsockopt(fd, SOL_CAN_RAW, CAN_RAW_RECV_OWN_MSGS, &own, sizeof(own));
  if (::setsockopt(fd, SOL_SOCKET, SO_RXQ_OVFL, &one, sizeof(one)) != 0) {
    return fail("setsockopt(SO_RXQ_OVFL)");
  }
  if (n_filters_ > 0) {
    can_filter f[kMaxFilters];
    for (int i = 0; i < n_filters_; ++i) {
      f[i].can_id = filters_[i].id;
      f[i].can_mask = filters_[i].mask;
    }
    if (::setsockopt(fd, SOL_CAN_RAW, CAN_RAW_FILTER, f, sizeof(can_filter) * n_filters_) != 0) {
      return fail("setsockopt(CAN_RAW_FILTER)");
    }
  }
  sockaddr_can addr{};
  addr.can_family = AF_CAN;
  addr.can_ifindex = static_cast<int>(idx);
  if (::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)) != 0) return fail("bind");
  fd_ = fd;
  last_ovfl_ = 0;  // the counter is per socket
  error_.clear();
  return true;
}

bool SocketCanTransport::set_filters(const CanFilter* filters, int n) {
  if (n < 0 || n > kMaxFilters) return false;
  for (int i = 0; i < n; ++i) filters_[i] = filters[i];
  n_filters_ = n;
  if (fd_ < 0) return false;
  can_filter f[kMaxFilters];
  for (int i = 0; i < n; ++i) {
    f[i].can_id = filters[i].id;
    f[i].can_mask = filters[i].mask;
  }
  // n == 0 installs no filter, i.e. receive nothing but error frames; use one match-all instead.
  if (n == 0) {
    f[0].can_id = 0;
    f[0].can_mask = 0;
    n = 1;
  }
  if (::setsockopt(fd_, SOL_CAN_RAW, CAN_RAW_FILTER, f, sizeof(can_filter) * n) != 0) {
    errno_ = errno;
    error_ = std::string("setsockopt(CAN_RAW_FILTER): ") + strerror(errno_);
    return false;
  }
  return true;
}

void SocketCanTransport::handle_error_frame(uint32_t id, const uint8_t* data) {
  ++stats_.error_frames;
  if (id & CAN_ERR_BUSOFF) {
    if (!bus_off_) ++stats_.bus_off_events;
    bus_off_ = true;
    bus_off_since_ns_ = now_ns();
  }
  if (id & CAN_ERR_RESTARTED) bus_off_ = false;
  (void)data;
}

CanIoStatus SocketCanTransport::send(const CanFrame& f) {
  if (bus_off_) return CanIoStatus::bus_off;
  if (fd_ < 0) return CanIoStatus::error;
  ssize_t r;
  size_t want;
  if (f.fd) {
    canfd_frame fr{};
    fr.can_id = f.id;
    fr.len = f.len;
    fr.flags = f.flags;
    std::memcpy(fr.data, f.data.data(), f.len <= 64 ? f.len : 64);
    want = sizeof(fr);
    r = ::write(fd_, &fr, want);
  } else {
    can_frame fr{};
    fr.can_id = f.id;
    fr.len = f.len <= 8 ? f.len : 8;
    std::memcpy(fr.data, f.data.data(), fr.len);
    want = sizeof(fr);
    r = ::write(fd_, &fr, want);
  }
  if (r == static_cast<ssize_t>(want)) {
    ++stats_.frames_sent;
    return CanIoStatus::ok;
  }
  ++stats_.send_errors;
  if (r < 0 && (errno == EAGAIN || errno == ENOBUFS)) return CanIoStatus::would_block;
  return CanIoStatus::error;
}

CanIoStatus SocketCanTransport::receive(CanFrame& f) {
  if (bus_off_ || fd_ < 0) {
    // Recovery: the kernel restarts the controller (restart-ms) and sends CAN_ERR_RESTARTED;
    // if that never comes, re-create the socket periodically so that a re-plugged interface or
    // a manual `ip link set canX up` is picked up.
    const int64_t now = now_ns();
    if (now - bus_off_since_ns_ > options_.reopen_period_ns) {
      close_socket();
      bus_off_since_ns_ = now;
      if (!open_socket()) return CanIoStatus::error;
      ++stats_.reopens;
    }
    if (fd_ < 0) return CanIoStatus::error;
  }
  canfd_frame fr{};
  ssize_t r = 0;
  for (;;) {
    iovec iov{&fr, sizeof(fr)};
    alignas(cmsghdr) char ctrl[CMSG_SPACE(sizeof(uint32_t))];
    msghdr msg{};
    msg.msg_iov = &iov;
    msg.msg_iovlen = 1;
    msg.msg_control = ctrl;
    msg.msg_controllen = sizeof(ctrl);
    r = ::recvmsg(fd_, &msg, MSG_DONTWAIT);
    if (r < 0) {
      if (errno == EAGAIN || errno == EWOULDBLOCK)
        return bus_off_ ? CanIoStatus::bus_off : CanIoStatus::empty;
      errno_ = errno;
      error_ = std::string("recvmsg on ") + options_.interface + ": " + strerror(errno_);
      if (errno_ == ENETDOWN || errno_ == ENODEV) close_socket();  // reopen on a later call
      return CanIoStatus::error;
    }
    for (cmsghdr* c = CMSG_FIRSTHDR(&msg); c != nullptr; c = CMSG_NXTHDR(&msg, c)) {
      if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SO_RXQ_OVFL) {
        uint32_t total = 0;
        std::memcpy(&total, CMSG_DATA(c), sizeof(total));
        stats_.rx_overflow_drops += total - last_ovfl_;  // the kernel reports a running total
        last_ovfl_ = total;
      }
    }
    if (r != static_cast<ssize_t>(CAN_MTU) && r != static_cast<ssize_t>(CANFD_MTU)) {
      ++stats_.malformed;
      return CanIoStatus::malformed;
    }
    if (fr.can_id & CAN_ERR_FLAG) {
      handle_error_frame(fr.can_id, fr.data);
      if (bus_off_) return CanIoStatus::bus_off;
      continue;  // counted; look for a data frame behind it
    }
    break;
  }
  bus_off_ = false;  // traffic flows again
  f.id = fr.can_id;
  f.fd = r == static_cast<ssize_t>(CANFD_MTU);
  f.len = f.fd ? fr.len : (fr.len <= 8 ? fr.len : 8);
  f.flags = f.fd ? fr.flags : 0;
  std::memcpy(f.data.data(), fr.data, f.len <= 64 ? f.len : 64);
  ++stats_.frames_received;
  return CanIoStatus::ok;
}

}  // namespace storey::drivers::can
