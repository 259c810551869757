#pragma once
// UDP ingestion of one LiDAR stream: a non-blocking socket woken by epoll (recvmmsg's own timeout
// is unreliable), datagrams drained in recvmmsg batches with kernel receive stamps
// (SO_TIMESTAMPNS), a source-address filter, decoding into fixed-size point chunks pushed through
// an rt::SpscQueue. Runs on the ingest thread (created by firmware/); after open() nothing
// allocates, locks or prints. Replay calls process_datagram() so that recorded packets take the
// very same path as live ones.
#include <netinet/in.h>
#include <sys/socket.h>

#include <array>
#include <atomic>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "drivers/lidar/mid360.hpp"
#include "drivers/lidar/vlp16.hpp"
#include "rt/spsc_queue.hpp"

struct mmsghdr;

namespace storey::drivers::lidar {

enum class SensorModel : uint8_t { vlp16, mid360 };

// One datagram's points. 9.2 KiB; the queue holds a fixed number of them.
struct PointChunk {
  static constexpr std::size_t kCapacity = kVlp16MaxPointsPerPacket;  // >= Mid-360's 96
  uint64_t sensor_stamp_ns = 0;  // VLP-16: us past the hour x 1000; Mid-360: header timestamp
  uint64_t receive_time_ns = 0;  // kernel receive time (CLOCK_REALTIME), or capture time
  uint64_t enqueue_time_ns = 0;  // CLOCK_REALTIME when pushed (packet-to-queue latency)
  uint32_t count = 0;
  uint32_t sequence = 0;  // datagrams accepted so far (gaps = chunks dropped on queue_full)
  uint8_t frame_cnt = 0;  // Mid-360 frame counter
  std::array<LidarPoint, kCapacity> points;
};

// Raw copy of an accepted datagram for recording (`storey run --record`), drained by a non-RT
// thread into a PcapWriter.
struct RawDatagram {
  uint64_t receive_time_ns = 0;
  uint32_t src_addr = 0, dst_addr = 0;  // host byte order
  uint16_t src_port = 0, dst_port = 0;
  uint16_t size = 0;
  std::array<uint8_t, 1500> data;
};

class UdpReceiver {
 public:
  struct Options {
    SensorModel sensor = SensorModel::vlp16;
    std::string bind_address = "0.0.0.0";
    uint16_t port = kVlp16DataPort;      // 0 = ephemeral (tests), see bound_port()
    uint32_t source_address = 0;         // host byte order; 0 accepts any sender
    int receive_buffer_bytes = 8 << 20;  // several MB: the 208 KiB default holds ~44 ms
    int batch = 64;                      // datagrams per recvmmsg call
    bool verify_crc = true;              // Mid-360
  };
  struct OpenStatus {
    bool ok = false;
    std::string error;       // why open failed (names address and port)
    std::string warning;     // e.g. receive buffer capped by net.core.rmem_max
    int receive_buffer = 0;  // what the kernel granted (getsockopt, as reported)
  };
  struct Counters {
    uint64_t datagrams = 0, accepted = 0, points = 0, imu = 0;
    uint64_t lost_udp_cnt = 0;    // Mid-360 packets missing from udp_cnt gaps (sensor/network loss)
    uint64_t record_dropped = 0;  // recording queue full
    std::array<uint64_t, kDropReasonCount> drops{};
  };

  UdpReceiver(Options opt, rt::SpscQueue<PointChunk>& out);
  ~UdpReceiver();
  UdpReceiver(const UdpReceiver&) = delete;
  UdpReceiver& operator=(const UdpReceiver&) = delete;

  OpenStatus open();
  void close();
  uint16_t bound_port() const { return bound_port_; }
  // The UDP socket (-1 before open()): the firmware's event-driven ingest task waits on it.
  int fd() const { return fd_; }

  // Optional taps, set before the ingest thread starts.
  void set_imu_queue(rt::SpscQueue<ImuSample>* q) { imu_out_ = q; }
  void set_record_queue(rt::SpscQueue<RawDatagram>* q) { record_ = q; }

  // Waits up to `timeout_ms` for data (epoll), then drains the socket. Returns datagrams read.
  int poll(int timeout_ms);

  // The per-datagram path shared by live and replay. `src_addr` host byte order.
  void process_datagram(std::span<const uint8_t> payload, uint32_t src_addr, uint16_t src_port,
                        uint64_t receive_time_ns);

  // Safe from any thread (relaxed atomics written by the ingest thread only).
  Counters counters() const;

 private:
  void drop(DropReason r);
  void record(std::span<const uint8_t> payload, uint32_t src_addr, uint16_t src_port,
              uint64_t receive_time_ns);
  void bump(std::atomic<uint64_t>& c, uint64_t n = 1) {
    c.store(c.load(std::memory_order_relaxed) + n, std::memory_order_relaxed);
  }

  Options opt_;
  rt::SpscQueue<PointChunk>& out_;
  rt::SpscQueue<ImuSample>* imu_out_ = nullptr;
  rt::SpscQueue<RawDatagram>* record_ = nullptr;
  Vlp16Decoder vlp16_;
  Mid360Decoder mid360_;
  int fd_ = -1;
  int epoll_fd_ = -1;
  uint16_t bound_port_ = 0;
  uint32_t bind_addr_ = 0;
  PointChunk scratch_;
  RawDatagram raw_scratch_;
  uint32_t sequence_ = 0;
  // recvmmsg buffers, allocated in open()
  std::vector<uint8_t> buffers_;
  std::vector<uint8_t> controls_;
  std::vector<sockaddr_in> addrs_;
  std::vector<struct iovec> iovs_;
  std::vector<::mmsghdr> msgs_;
  // counters
  std::atomic<uint64_t> datagrams_{0}, accepted_{0}, points_{0}, imu_{0}, lost_{0},
      record_dropped_{0};
  std::array<std::atomic<uint64_t>, kDropReasonCount> drops_{};
};

// Reads /proc/sys/net/core/rmem_max; -1 if unreadable.
long read_rmem_max();

}  // namespace storey::drivers::lidar
