#pragma once
// The firmware's Platform (platform.hpp) on the live robot (`storey run`): the LiDAR over UDP
// (drivers/lidar UdpReceiver -> PointChunk queue -> ScanAssembler, deskewed per point with the
// pose history) and the Go2 over a RobotLink (DDS, UDP or CAN). The same code runs against
// `storey-sim --config` (hardware-in-the-loop): it cannot tell the simulator from the robot.
//
// Threads (DESIGN §3): take_scan() runs on the ingest task (woken by the LiDAR socket,
// lidar_fd()); latest_pose(), send_command() and link() on the control task, which is the only
// thread touching the RobotLink. The two share the pose history (firmware/pose_history.hpp,
// lock-free, one writer). Counters are relaxed atomics readable from any thread. After open()
// nothing allocates in either path (the DDS link's writes aside, see drivers/go2/README.md).
//
// Times: the firmware clock is CLOCK_MONOTONIC. Robot states are stamped with their receive time
// on that clock; LiDAR packets carry the kernel's CLOCK_REALTIME receive stamp, moved onto the
// monotonic timeline with the current offset between the two clocks and back-dated by the
// packet's own duration (its last point left the sensor when the datagram did).
#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <string>

#include "config/parameters.hpp"
#include "drivers/go2/robot_link.hpp"
#include "drivers/lidar/scan_assembler.hpp"
#include "drivers/lidar/udp_receiver.hpp"
#include "firmware/platform.hpp"
#include "firmware/pose_history.hpp"
#include "rt/clock.hpp"
#include "rt/mailbox.hpp"
#include "rt/spsc_queue.hpp"

namespace storey::firmware {

struct LivePlatformOptions {
  config::Parameters params;
  std::size_t chunk_queue = 512;  // decoded packets in flight (~0.7 s of VLP-16, 0.25 s Mid-360)
  std::size_t record_queue = 0;   // > 0: raw datagrams tapped for `--record` (drain_record)
  double max_extrapolation_s = 0.15;  // newest LiDAR points may be this far past the last state
  double default_body_height_m =
      kBodyCentreHeightM;  // Go2 body centre above the feet when not reported
  // Receive port override (tests: 0 = ephemeral); < 0 = params.sensor.data_port.
  int data_port = -1;
};

// Counters of the live platform (totals since open()).
struct LiveCounters {
  std::uint64_t scans = 0;                // delivered to the firmware
  std::uint64_t scans_without_pose = 0;   // dropped: no pose for the scan's end (before the
                                          // first robot state, or the link is gone)
  std::uint64_t points_without_pose = 0;  // left undeskewed inside a delivered scan
  std::uint64_t points_out_of_range = 0;  // outside sensor.min/max_range_m, or not finite
  std::uint64_t points_overflowed = 0;    // beyond a scan buffer's capacity
  std::uint64_t states = 0;               // new robot states seen by the control task
  std::uint64_t frozen_states = 0;        // states whose sample stamp did not advance
  std::uint64_t commands_sent = 0;
  std::uint64_t commands_refused = 0;  // by the link: stale, invalid, would block, send failed
  std::uint64_t history_refused = 0;   // states not added to the pose history (time went back)
};

class LivePlatform final : public Platform {
 public:
  // `link` must be open (see make_robot_link). `clock` is the firmware's (monotonic) clock.
  LivePlatform(const LivePlatformOptions& options, std::unique_ptr<drivers::go2::RobotLink> link,
               const rt::Clock& clock);
  ~LivePlatform() override;
  LivePlatform(const LivePlatform&) = delete;
  LivePlatform& operator=(const LivePlatform&) = delete;

  // Opens the LiDAR socket (bind, SO_RCVBUF, SO_TIMESTAMPNS, source filter). The status carries
  // the error (not ok) or a warning (e.g. receive buffer capped by net.core.rmem_max) for the
  // caller to print once.
  drivers::lidar::UdpReceiver::OpenStatus open();
  // The LiDAR socket for the ingest row of the task table (-1 before open()).
  int lidar_fd() const { return lidar_fd_; }
  uint16_t lidar_port() const { return receiver_->bound_port(); }

  // Platform (see platform.hpp for the calling threads).
  bool take_scan(ScanBuffer& out) override;
  bool latest_pose(PoseSample& out) override;
  void send_command(const VelocityCommand& cmd) override;
  LinkHealth link() override;

  // Main thread, once the tasks have stopped: zero velocity and the robot's own stop request
  // (StopMove), stamped now. False if the link refused either.
  bool command_stop();

  // `--record`: the raw datagram tap (nullptr unless options.record_queue > 0). One consumer
  // (a non-RT thread).
  rt::SpscQueue<drivers::lidar::RawDatagram>* record_queue() { return record_.get(); }

  // Any thread.
  drivers::lidar::UdpReceiver::Counters lidar_counters() const { return receiver_->counters(); }
  LiveCounters counters() const;
  // The latest odometry as the control task saw it (progress line, trajectory length); false
  // before the first robot state.
  bool read_pose(PoseSample& out) const { return pose_out_.read(out) != 0; }
  // Control task or after stop: the link's own health counters.
  drivers::go2::LinkHealth link_health() { return link_->health(clock_.now_ns()); }
  const PoseHistory& pose_history() const { return history_; }

  // Body pose -> firmware odometry sample: the ground point under the body centre, yaw, body
  // frame velocity. Exposed for tests.
  static PoseSample to_pose_sample(const drivers::go2::RobotState& s, double default_body_height_m,
                                   double stamp_s);

 private:
  class Deskew;
  class Sink;
  void bump(std::atomic<std::uint64_t>& c, std::uint64_t n = 1) {
    c.store(c.load(std::memory_order_relaxed) + n, std::memory_order_relaxed);
  }

  LivePlatformOptions opt_;
  std::unique_ptr<drivers::go2::RobotLink> link_;
  const rt::Clock& clock_;

  // ingest task
  rt::SpscQueue<drivers::lidar::PointChunk> chunks_;
  std::unique_ptr<rt::SpscQueue<drivers::lidar::RawDatagram>> record_;
  std::unique_ptr<drivers::lidar::UdpReceiver> receiver_;
  std::unique_ptr<Deskew> deskew_;
  std::unique_ptr<Sink> sink_;
  std::unique_ptr<drivers::lidar::ScanAssembler> assembler_;
  drivers::lidar::PointChunk chunk_;  // scratch (9 KiB: not on the task's stack)
  int lidar_fd_ = -1;

  // control task -> ingest task
  PoseHistory history_;

  // control task
  std::int64_t last_rx_ns_ = -1, last_sample_ns_ = INT64_MIN;
  PoseSample pose_;  // the latest odometry, stamped when its sample time last advanced
  bool have_pose_ = false;
  rt::Mailbox<PoseSample> pose_out_;

  std::atomic<std::uint64_t> scans_{0}, scans_without_pose_{0}, points_without_pose_{0},
      out_of_range_{0}, overflowed_{0}, states_{0}, frozen_{0}, sent_{0}, refused_{0};
};

}  // namespace storey::firmware
