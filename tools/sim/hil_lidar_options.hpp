// Options shared by the hardware-in-the-loop LiDAR packet sources (hil_vlp16_source.hpp,
// hil_mid360_source.hpp).
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <functional>
#include <span>

namespace storey::tools::sim {

struct HilLidarOptions {
  // Sensor pose in the sim's body frame (origin on the ground under the body centre, x forward,
  // z up). Points in the packets are in this sensor frame.
  Eigen::Isometry3d mount = Eigen::Translation3d(0.10, 0.0, 0.50) * Eigen::Quaterniond::Identity();
  double min_range = 0.3;           // [m] closer hits give no return
  double max_range = 0.0;           // [m]; 0 = sensor default (VLP-16 100 m, Mid-360 40 m)
  double range_noise_sigma = 0.02;  // [m] gaussian along the beam
  double dropout = 0.0;             // probability that a return is lost
  double rotation_hz = 10.0;        // VLP-16 spin rate / Mid-360 frame rate [Hz]
  double mid360_points_per_second = 200000.0;
  uint8_t reflectivity = 100;  // the ray caster has no material: one value for every return
  // Sensor clock [ns] at simulated time 0: packet stamps are epoch + simulated time.
  int64_t clock_epoch_ns = 0;
  uint64_t seed = 1;
};

// Receives each encoded datagram (valid only during the call).
using HilEmit = std::function<void(std::span<const uint8_t>)>;

}  // namespace storey::tools::sim
