// Simulated LiDARs ray cast with Embree (DESIGN §5): Velodyne VLP-16 and Livox Mid-360, mounted
// on the robot, with min/max range, gaussian range noise, dropouts and per-point timestamps; the
// robot keeps moving during the sweep (pose queried per batch of 16 rays).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <functional>
#include <vector>

#include "tools/sim/ray_caster.hpp"
#include "tools/sim/rng.hpp"

namespace storey::tools::sim {

enum class LidarType { vlp16, mid360 };

struct LidarOptions {
  LidarType type = LidarType::vlp16;
  // Sensor pose in the body frame (origin on the ground under the body centre, x forward, z up).
  Eigen::Isometry3d mount = Eigen::Translation3d(0.10, 0.0, 0.50) * Eigen::Quaterniond::Identity();
  double min_range = 0.3;           // [m]
  double max_range = 0.0;           // [m]; 0 = sensor default (VLP-16 100 m, Mid-360 40 m)
  double range_noise_sigma = 0.02;  // [m], gaussian along the beam
  double dropout = 0.0;             // probability that a return is lost
  double scan_period = 0.1;         // [s], 10 Hz
  double mid360_points_per_second = 200000.0;
  uint64_t seed = 1;
};

// One sweep. Points are returns only (misses and dropouts are not listed).
struct LidarScan {
  double t_start = 0.0, t_end = 0.0;           // [s] virtual time of the sweep
  std::vector<Eigen::Vector3f> points_world;   // [m] measured point in the world frame
  std::vector<Eigen::Vector3f> points_sensor;  // [m] the same in the sensor frame at its time
  std::vector<Eigen::Vector3f> origins_world;  // [m] sensor origin when the point was measured
  std::vector<float> times;                    // [s] since t_start
  std::vector<uint8_t> channels;               // VLP-16: laser id (firing order); Mid-360: 0-3
  Eigen::Isometry3d sensor_pose_start = Eigen::Isometry3d::Identity();  // world <- sensor
  std::size_t rays = 0;     // rays cast (returns + misses + dropouts)
  std::size_t dropped = 0;  // returns removed by dropout
  std::size_t size() const { return points_world.size(); }
  void clear();
};

// world <- body at a virtual time [s].
using PoseAtTime = std::function<Eigen::Isometry3d(double)>;

class LidarModel {
 public:
  // VLP-16 geometry (VLP-16 user manual, ch. 9): lasers fire in this order every 2.304 us,
  // one firing sequence (16 lasers) every 55.296 us; 0.2 deg azimuth per sequence at 10 Hz.
  static constexpr double kVlpElevationDeg[16] = {-15, 1, -13, 3,  -11, 5,  -9, 7,
                                                  -7,  9, -5,  11, -3,  13, -1, 15};
  static constexpr double kVlpFiringPeriod = 55.296e-6;  // [s]
  static constexpr double kVlpLaserPeriod = 2.304e-6;    // [s]
  static constexpr int kVlpFirings = 1800;               // 360 deg / 0.2 deg
  static constexpr double kMidElevationMinDeg = -7.0, kMidElevationMaxDeg = 52.0;

  LidarModel(const RayCaster& world, const LidarOptions& options);
  const LidarOptions& options() const { return opt_; }
  // Rays per sweep (VLP-16: 28,800; Mid-360: rate x period).
  std::size_t rays_per_scan() const;
  // Casts one sweep starting at t_start; pose(t) gives the body pose at each batch's time.
  // Reuses out's storage (no allocation once it has grown).
  void scan(double t_start, const PoseAtTime& pose, LidarScan& out);

 private:
  // Direction (sensor frame, unit) and time offset [s] of ray i of the current sweep.
  void ray(std::size_t i, Eigen::Vector3f* dir, double* t, uint8_t* channel) const;

  const RayCaster& world_;
  LidarOptions opt_;
  Rng rng_;
  uint64_t mid_index_ = 0;  // Mid-360: global point index (the pattern never repeats)
  std::vector<float> vlp_cos_el_, vlp_sin_el_;
};

}  // namespace storey::tools::sim
