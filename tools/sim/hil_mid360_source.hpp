// Livox Mid-360 for hardware-in-the-loop: the lockstep LidarModel's non-repetitive pattern, cast
// in short slices (its point counter runs on, so slices join into the same pattern) and packed
// 96 points per Livox SDK2 packet, data type 1 (cartesian high, mm, sensor frame x forward,
// y left, z up) with the drivers/lidar encoder: time_interval (0.1 us), udp_cnt restarting at
// each frame, frame_cnt at rotation_hz, CRC-32. Like the real sensor every packet holds 96
// consecutive shots; a shot without a return is sent as x = y = z = 0 (the decoder skips it).
#pragma once

#include <array>
#include <cstdint>
#include <memory>

#include "drivers/lidar/mid360.hpp"
#include "tools/sim/hil_lidar_options.hpp"
#include "tools/sim/lidar_model.hpp"

namespace storey::tools::sim {

class HilMid360Source {
 public:
  // `slice` [s] is how much simulated time one cast covers (the HIL loop's step).
  HilMid360Source(const RayCaster& world, const HilLidarOptions& options, double slice);

  // Casts the slices that end at or before t [s] and emits every packet whose 96 shots are all
  // cast. pose(t) must cover every time since the previous call. Returns packets emitted.
  int produce(double t, const PoseAtTime& pose, const HilEmit& emit);
  // Sensor clock [ns] at simulated time 0 (set before the first produce()).
  void set_clock_epoch(int64_t ns) { opt_.clock_epoch_ns = ns; }
  uint64_t packets() const { return packet_; }
  uint64_t returns() const { return returns_; }

 private:
  void emit_packet(const HilEmit& emit);

  HilLidarOptions opt_;
  std::unique_ptr<LidarModel> model_;
  LidarScan scan_;
  uint64_t shots_per_slice_ = 0;
  uint64_t shots_per_frame_ = 0;
  uint64_t shot_ = 0;    // shots cast so far (global index of the next one)
  uint64_t packet_ = 0;  // index of the packet being filled (its first shot = 96 * packet_)
  uint64_t returns_ = 0;
  std::array<drivers::lidar::LidarPoint, drivers::lidar::kMid360MaxPointsPerPacket> slots_{};
  std::array<uint8_t,
             drivers::lidar::mid360_packet_size(drivers::lidar::Mid360DataType::cartesian_high,
                                                drivers::lidar::kMid360MaxPointsPerPacket)>
      buf_{};
};

}  // namespace storey::tools::sim
