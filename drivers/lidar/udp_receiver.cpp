#include "drivers/lidar/udp_receiver.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <sys/epoll.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <ctime>

namespace storey::drivers::lidar {

namespace {
constexpr std::size_t kBufSize = 2048;  // > any LiDAR datagram (1380 max); larger ones: bad_size
constexpr std::size_t kCtlSize = CMSG_SPACE(sizeof(timespec));

uint64_t realtime_ns() {
  timespec ts;
  clock_gettime(CLOCK_REALTIME, &ts);
  return static_cast<uint64_t>(ts.tv_sec) * 1000000000ull + static_cast<uint64_t>(ts.tv_nsec);
}
}  // namespace

long read_rmem_max() {
  std::FILE* f = std::fopen("/proc/sys/net/core/rmem_max", "r");
  if (f == nullptr) return -1;
  long v = -1;
  if (std::fscanf(f, "%ld", &v) != 1) v = -1;
  std::fclose(f);
  return v;
}

UdpReceiver::UdpReceiver(Options opt, rt::SpscQueue<PointChunk>& out)
    : opt_(std::move(opt)),
      out_(out),
      mid360_(Mid360Decoder::Options{.verify_crc = opt_.verify_crc}) {}

UdpReceiver::~UdpReceiver() {
  close();
}

void UdpReceiver::close() {
  if (epoll_fd_ >= 0) ::close(epoll_fd_);
  if (fd_ >= 0) ::close(fd_);
  epoll_fd_ = fd_ = -1;
}

UdpReceiver::OpenStatus UdpReceiver::open() {
  OpenStatus st;
  close();
  const std::string where = opt_.bind_address + ":" + std::to_string(opt_.port);
  fd_ = ::socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd_ < 0) {
    st.error = "udp " + where + ": socket: " + std::strerror(errno);
    return st;
  }
  const int one = 1;
  ::setsockopt(fd_, SOL_SOCKET, SO_REUSEADDR, &one, sizeof(one));
  // Ask for the buffer; SO_RCVBUFFORCE passes rmem_max when privileged, else SO_RCVBUF is capped.
  const int want = opt_.receive_buffer_bytes;
  if (::setsockopt(fd_, SOL_SOCKET, SO_RCVBUFFORCE, &want, sizeof(want)) != 0) {
    ::setsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &want, sizeof(want));
  }
  int got = 0;
  socklen_t len = sizeof(got);
  ::getsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &got, &len);
  st.receive_buffer = got;
  if (got / 2 < want) {  // the kernel reports twice the usable size it granted
    st.warning = "udp " + where + ": receive buffer " + std::to_string(got / 2) +
                 " bytes instead of " + std::to_string(want) +
                 " (net.core.rmem_max = " + std::to_string(read_rmem_max()) +
                 "); raise it: sysctl -w net.core.rmem_max=" + std::to_string(want);
  }
  if (::setsockopt(fd_, SOL_SOCKET, SO_TIMESTAMPNS, &one, sizeof(one)) != 0) {
    st.warning += (st.warning.empty() ? "" : "; ") + std::string("SO_TIMESTAMPNS unavailable: ") +
                  std::strerror(errno) + " (user-space receive times used)";
  }
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(opt_.port);
  if (::inet_pton(AF_INET, opt_.bind_address.c_str(), &addr.sin_addr) != 1) {
    st.error = "udp " + where + ": bad bind address";
    close();
    return st;
  }
  if (::bind(fd_, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)) != 0) {
    st.error = "udp " + where + ": bind: " + std::strerror(errno);
    close();
    return st;
  }
  bind_addr_ = ntohl(addr.sin_addr.s_addr);
  sockaddr_in bound{};
  socklen_t blen = sizeof(bound);
  ::getsockname(fd_, reinterpret_cast<sockaddr*>(&bound), &blen);
  bound_port_ = ntohs(bound.sin_port);
  epoll_fd_ = ::epoll_create1(EPOLL_CLOEXEC);
  epoll_event ev{};
  ev.events = EPOLLIN;
  ev.data.fd = fd_;
  if (epoll_fd_ < 0 || ::epoll_ctl(epoll_fd_, EPOLL_CTL_ADD, fd_, &ev) != 0) {
    st.error = "udp " + where + ": epoll: " + std::strerror(errno);
    close();
    return st;
  }
  const std::size_t n = static_cast<std::size_t>(opt_.batch > 0 ? opt_.batch : 1);
  buffers_.assign(n * kBufSize, 0);
  controls_.assign(n * kCtlSize, 0);
  addrs_.assign(n, sockaddr_in{});
  iovs_.assign(n, iovec{});
  msgs_.assign(n, ::mmsghdr{});
  st.ok = true;
  return st;
}

int UdpReceiver::poll(int timeout_ms) {
  if (fd_ < 0) return 0;
  epoll_event ev;
  if (::epoll_wait(epoll_fd_, &ev, 1, timeout_ms) <= 0) return 0;
  int total = 0;
  const unsigned n = static_cast<unsigned>(msgs_.size());
  for (;;) {
    for (unsigned i = 0; i < n; ++i) {
      iovs_[i].iov_base = buffers_.data() + i * kBufSize;
      iovs_[i].iov_len = kBufSize;
      msghdr& h = msgs_[i].msg_hdr;
      h.msg_name = &addrs_[i];
      h.msg_namelen = sizeof(sockaddr_in);
      h.msg_iov = &iovs_[i];
      h.msg_iovlen = 1;
      h.msg_control = controls_.data() + i * kCtlSize;
      h.msg_controllen = kCtlSize;
      h.msg_flags = 0;
    }
    const int got = ::recvmmsg(fd_, msgs_.data(), n, MSG_DONTWAIT, nullptr);
    if (got <= 0) break;  // EAGAIN: drained
    for (int i = 0; i < got; ++i) {
      msghdr& h = msgs_[i].msg_hdr;
      uint64_t t = 0;
      for (cmsghdr* c = CMSG_FIRSTHDR(&h); c != nullptr; c = CMSG_NXTHDR(&h, c)) {
        if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SCM_TIMESTAMPNS) {
          timespec ts;
          std::memcpy(&ts, CMSG_DATA(c), sizeof(ts));
          t = static_cast<uint64_t>(ts.tv_sec) * 1000000000ull + static_cast<uint64_t>(ts.tv_nsec);
        }
      }
      if (t == 0) t = realtime_ns();
      std::size_t size = msgs_[i].msg_len;
      if ((h.msg_flags & MSG_TRUNC) != 0) {  // larger than any LiDAR datagram
        bump(datagrams_);
        drop(DropReason::bad_size);
        continue;
      }
      const uint8_t* data = buffers_.data() + i * kBufSize;
      process_datagram(std::span<const uint8_t>(data, size), ntohl(addrs_[i].sin_addr.s_addr),
                       ntohs(addrs_[i].sin_port), t);
    }
    total += got;
    if (static_cast<unsigned>(got) < n) break;
  }
  return total;
}

void UdpReceiver::drop(DropReason r) {
  bump(drops_[static_cast<std::size_t>(r)]);
}

void UdpReceiver::process_datagram(std::span<const uint8_t> payload, uint32_t src_addr,
                                   uint16_t src_port, uint64_t receive_time_ns) {
  bump(datagrams_);
  if (opt_.source_address != 0 && src_addr != opt_.source_address) {
    drop(DropReason::wrong_source);
    return;
  }
  PointChunk* chunk = &scratch_;  // decoded here, copied into the queue slot by try_push
  chunk->count = 0;
  chunk->frame_cnt = 0;
  DropReason reason = DropReason::none;
  if (opt_.sensor == SensorModel::vlp16) {
    const Vlp16PacketInfo info = vlp16_.decode(payload, chunk->points);
    reason = info.reason;
    chunk->count = info.points;
    chunk->sensor_stamp_ns = static_cast<uint64_t>(info.timestamp_us) * 1000u;
  } else {
    ImuSample imu;
    const Mid360PacketInfo info = mid360_.decode(payload, chunk->points, &imu);
    reason = info.reason;
    lost_.store(mid360_.lost_packets(), std::memory_order_relaxed);
    if (reason == DropReason::none && info.imu) {
      bump(imu_);
      bump(accepted_);
      record(payload, src_addr, src_port, receive_time_ns);
      if (imu_out_ != nullptr && !imu_out_->try_push(imu)) drop(DropReason::queue_full);
      return;
    }
    chunk->count = info.points;
    chunk->frame_cnt = info.frame_cnt;
    chunk->sensor_stamp_ns = info.timestamp_ns;
  }
  if (reason != DropReason::none) {
    drop(reason);
    return;
  }
  bump(accepted_);
  record(payload, src_addr, src_port, receive_time_ns);
  chunk->receive_time_ns = receive_time_ns;
  chunk->sequence = ++sequence_;
  chunk->enqueue_time_ns = realtime_ns();
  if (!out_.try_push(*chunk)) {
    drop(DropReason::queue_full);
    return;
  }
  bump(points_, chunk->count);
}

void UdpReceiver::record(std::span<const uint8_t> payload, uint32_t src_addr, uint16_t src_port,
                         uint64_t receive_time_ns) {
  if (record_ == nullptr) return;
  RawDatagram& r = raw_scratch_;
  if (payload.size() > r.data.size()) return;
  r.receive_time_ns = receive_time_ns;
  r.src_addr = src_addr;
  r.src_port = src_port;
  r.dst_addr = bind_addr_;
  r.dst_port = bound_port_;
  r.size = static_cast<uint16_t>(payload.size());
  std::memcpy(r.data.data(), payload.data(), payload.size());
  if (!record_->try_push(r)) bump(record_dropped_);
}

UdpReceiver::Counters UdpReceiver::counters() const {
  Counters c;
  c.datagrams = datagrams_.load(std::memory_order_relaxed);
  c.accepted = accepted_.load(std::memory_order_relaxed);
  c.points = points_.load(std::memory_order_relaxed);
  c.imu = imu_.load(std::memory_order_relaxed);
  c.lost_udp_cnt = lost_.load(std::memory_order_relaxed);
  c.record_dropped = record_dropped_.load(std::memory_order_relaxed);
  for (std::size_t i = 0; i < kDropReasonCount; ++i) {
    c.drops[i] = drops_[i].load(std::memory_order_relaxed);
  }
  return c;
}

}  // namespace storey::drivers::lidar
