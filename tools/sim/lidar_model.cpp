#include "tools/sim/lidar_model.hpp"

#include <cmath>
#include <stdexcept>

namespace storey::tools::sim {

void LidarScan::clear() {
  points_world.clear();
  points_sensor.clear();
  origins_world.clear();
  times.clear();
  channels.clear();
  rays = dropped = 0;
}

LidarModel::LidarModel(const RayCaster& world, const LidarOptions& options)
    : world_(world), opt_(options), rng_(options.seed) {
  if (opt_.max_range <= 0.0) opt_.max_range = opt_.type == LidarType::vlp16 ? 100.0 : 40.0;
  if (!(opt_.min_range >= 0.0 && opt_.min_range < opt_.max_range))
    throw std::runtime_error("lidar: need 0 <= min_range < max_range");
  if (!(opt_.scan_period > 0.0)) throw std::runtime_error("lidar: scan_period must be > 0");
  if (!(opt_.dropout >= 0.0 && opt_.dropout <= 1.0))
    throw std::runtime_error("lidar: dropout must be within 0..1");
  if (!(opt_.range_noise_sigma >= 0.0)) throw std::runtime_error("lidar: noise sigma must be >= 0");
  if (opt_.type == LidarType::mid360 && !(opt_.mid360_points_per_second > 0.0))
    throw std::runtime_error("lidar: mid360_points_per_second must be > 0");
  for (double e : kVlpElevationDeg) {
    vlp_cos_el_.push_back(float(std::cos(e * M_PI / 180.0)));
    vlp_sin_el_.push_back(float(std::sin(e * M_PI / 180.0)));
  }
}

std::size_t LidarModel::rays_per_scan() const {
  if (opt_.type == LidarType::vlp16) return std::size_t(kVlpFirings) * 16;
  return static_cast<std::size_t>(std::llround(opt_.mid360_points_per_second * opt_.scan_period));
}

void LidarModel::ray(std::size_t i, Eigen::Vector3f* dir, double* t, uint8_t* channel) const {
  if (opt_.type == LidarType::vlp16) {
    const std::size_t firing = i / 16, laser = i % 16;
    *t = double(firing) * kVlpFiringPeriod + double(laser) * kVlpLaserPeriod;
    // The head keeps turning between lasers of one sequence (0.2 deg per 55.296 us).
    const double az = (double(firing) + double(laser) * kVlpLaserPeriod / kVlpFiringPeriod) *
                      (0.2 * M_PI / 180.0);
    const float ca = float(std::cos(az)), sa = float(std::sin(az));
    *dir = {vlp_cos_el_[laser] * ca, vlp_cos_el_[laser] * sa, vlp_sin_el_[laser]};
    *channel = uint8_t(laser);
    return;
  }
  // Mid-360 stand-in for its non-repetitive rosette: four heads 90 deg apart in azimuth, each
  // turning at 10 rev/s while its elevation sweeps -7..52 deg as a triangle wave at
  // 1000 * golden-ratio Hz. The ratio is irrational, so successive frames interleave instead of
  // repeating and coverage fills in over time, like the real sensor.
  const uint64_t n = mid_index_ + i;
  const double rate = opt_.mid360_points_per_second;
  *t = double(i) / rate;
  const double tg = double(n) / rate;  // time on the sensor's own clock
  const int head = int(n % 4);
  const double az = 2.0 * M_PI * (10.0 * tg) + head * (M_PI / 2.0);
  double ph = tg * 1618.0339887 + head * 0.25;
  ph -= std::floor(ph);
  const double tri = ph < 0.5 ? 2.0 * ph : 2.0 - 2.0 * ph;
  const double el =
      (kMidElevationMinDeg + (kMidElevationMaxDeg - kMidElevationMinDeg) * tri) * M_PI / 180.0;
  *dir = {float(std::cos(el) * std::cos(az)), float(std::cos(el) * std::sin(az)),
          float(std::sin(el))};
  *channel = uint8_t(head);
}

void LidarModel::scan(double t_start, const PoseAtTime& pose, LidarScan& out) {
  out.clear();
  out.t_start = t_start;
  out.t_end = t_start + opt_.scan_period;
  out.sensor_pose_start = pose(t_start) * opt_.mount;
  const std::size_t n = rays_per_scan();
  out.rays = n;
  RayPacket16 pk;
  Eigen::Vector3f dirs[16];
  double times[16];
  uint8_t chans[16];
  const float tmax = float(opt_.max_range + 5.0 * opt_.range_noise_sigma + 0.01);
  for (std::size_t b = 0; b < n; b += 16) {
    const std::size_t m = std::min<std::size_t>(16, n - b);
    for (std::size_t k = 0; k < m; ++k) ray(b + k, &dirs[k], &times[k], &chans[k]);
    // One pose per batch: 16 rays span <= 80 us, i.e. < 0.1 mm of motion at 1 m/s.
    const Eigen::Isometry3d ws = pose(t_start + times[0]) * opt_.mount;
    const Eigen::Matrix3f R = ws.linear().cast<float>();
    const Eigen::Vector3f o = ws.translation().cast<float>();
    for (std::size_t k = 0; k < 16; ++k) {
      pk.valid[k] = k < m;
      const Eigen::Vector3f d = k < m ? Eigen::Vector3f(R * dirs[k]) : Eigen::Vector3f::UnitX();
      pk.ox[k] = o.x(), pk.oy[k] = o.y(), pk.oz[k] = o.z();
      pk.dx[k] = d.x(), pk.dy[k] = d.y(), pk.dz[k] = d.z();
      pk.tmax[k] = tmax;
    }
    world_.cast16(pk);
    for (std::size_t k = 0; k < m; ++k) {
      if (pk.distance[k] < 0.f) continue;
      // Noise and dropout are drawn only for returns, in ray order: deterministic per seed.
      const double r = pk.distance[k] + opt_.range_noise_sigma * rng_.normal();
      if (opt_.dropout > 0.0 && rng_.uniform() < opt_.dropout) {
        ++out.dropped;
        continue;
      }
      if (r < opt_.min_range || r > opt_.max_range) continue;
      const Eigen::Vector3f ps = dirs[k] * float(r);
      out.points_sensor.push_back(ps);
      out.points_world.push_back(R * ps + o);
      out.origins_world.push_back(o);
      out.times.push_back(float(times[k]));
      out.channels.push_back(chans[k]);
    }
  }
  if (opt_.type == LidarType::mid360) mid_index_ += n;
}

}  // namespace storey::tools::sim
