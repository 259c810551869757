#include "tools/sim/hil_vlp16_source.hpp"

#include <cmath>
#include <stdexcept>

namespace storey::tools::sim {

namespace lidar = storey::drivers::lidar;

HilVlp16Source::HilVlp16Source(const RayCaster& world, const HilLidarOptions& options)
    : world_(world), opt_(options), rng_(options.seed) {
  if (opt_.max_range <= 0.0) opt_.max_range = 100.0;
  // Beyond 131 m the 2 mm unit of a u16 overflows.
  opt_.max_range = std::min(opt_.max_range, 131.0);
  if (!(opt_.min_range >= 0.0 && opt_.min_range < opt_.max_range))
    throw std::runtime_error("hil vlp16: need 0 <= min_range < max_range");
  // 5-20 Hz is the VLP-16's range (300-1200 rpm); the decoder refuses faster block steps.
  if (!(opt_.rotation_hz >= 5.0 && opt_.rotation_hz <= 20.0))
    throw std::runtime_error("hil vlp16: rotation rate must be 5..20 Hz (sensor.scan_rate_hz)");
  if (!(opt_.range_noise_sigma >= 0.0) || !(opt_.dropout >= 0.0 && opt_.dropout <= 1.0))
    throw std::runtime_error("hil vlp16: need noise sigma >= 0 and dropout within 0..1");
  for (int l = 0; l < 16; ++l) {
    const double w = lidar::kVlp16ElevationDeg[l] * M_PI / 180.0;
    cos_el_[l] = float(std::cos(w));
    sin_el_[l] = float(std::sin(w));
  }
}

uint16_t HilVlp16Source::firing_azimuth(uint64_t firing) const {
  // Turns since time 0 at the firing's start, in 0.01 deg, rounded.
  const double turns = firing_time(firing) * opt_.rotation_hz;
  const double cdeg = (turns - std::floor(turns)) * 36000.0;
  return uint16_t(uint32_t(std::llround(cdeg)) % lidar::kVlp16AzimuthUnits);
}

int HilVlp16Source::produce(double t, const PoseAtTime& pose, const HilEmit& emit) {
  using namespace lidar;
  int n = 0;
  for (;;) {
    const uint64_t last = next_packet_ * kVlp16FiringsPerPacket + kVlp16FiringsPerPacket - 1;
    // The packet leaves the sensor once its last laser has fired.
    if (firing_time(last) + 15 * kVlp16LaserNs * 1e-9 > t + 1e-12) break;
    cast_packet(next_packet_, pose);
    const uint64_t first = next_packet_ * kVlp16FiringsPerPacket;
    const int64_t stamp_ns = opt_.clock_epoch_ns + int64_t(std::llround(firing_time(first) * 1e9));
    // Microseconds past the hour of the packet's first firing (VLP-16 manual 9.3.1).
    const uint32_t us_past_hour = uint32_t((stamp_ns / 1000) % 3'600'000'000LL);
    const std::size_t bytes = vlp16_encode_firings(
        firings_, us_past_hour, Vlp16ReturnMode::strongest, kVlp16ProductVlp16, buf_);
    if (bytes == kVlp16DataPacketSize && emit) emit(std::span<const uint8_t>(buf_.data(), bytes));
    ++next_packet_;
    ++n;
  }
  return n;
}

void HilVlp16Source::cast_packet(uint64_t packet, const PoseAtTime& pose) {
  using namespace lidar;
  const uint64_t first = packet * kVlp16FiringsPerPacket;
  // Block azimuths and the per-block step the decoder derives from them (vlp16_validate: the
  // last block reuses the previous step).
  std::array<uint16_t, kVlp16Blocks> az{};
  std::array<uint32_t, kVlp16Blocks> gap{};
  for (int b = 0; b < kVlp16Blocks; ++b) az[b] = firing_azimuth(first + 2 * b);
  for (int b = 0; b + 1 < kVlp16Blocks; ++b)
    gap[b] = (az[b + 1] + kVlp16AzimuthUnits - az[b]) % kVlp16AzimuthUnits;
  gap[kVlp16Blocks - 1] = gap[kVlp16Blocks - 2];

  const float tmax = float(opt_.max_range + 5.0 * opt_.range_noise_sigma + 0.01);
  RayPacket16 pk;
  Eigen::Vector3f dirs[16];
  for (int f = 0; f < kVlp16FiringsPerPacket; ++f) {
    const int b = f / 2, fi = f % 2;
    Vlp16Firing& out = firings_[f];
    out.azimuth_cdeg = az[b];
    // One pose per firing sequence: its 16 lasers span 35 us (< 0.04 mm at 1 m/s).
    const Eigen::Isometry3d ws = pose(firing_time(first + f)) * opt_.mount;
    const Eigen::Matrix3f R = ws.linear().cast<float>();
    const Eigen::Vector3f o = ws.translation().cast<float>();
    for (int l = 0; l < 16; ++l) {
      // The decoder's interpolation (vlp16_for_each_return), integer for integer.
      const uint32_t dt = kVlp16FiringNs * fi + kVlp16LaserNs * l;
      const uint32_t daz = (2 * gap[b] * dt + kVlp16BlockNs) / (2 * kVlp16BlockNs);
      const double a = double((az[b] + daz) % kVlp16AzimuthUnits) * (M_PI / 18000.0);
      dirs[l] = {cos_el_[l] * float(std::sin(a)), cos_el_[l] * float(std::cos(a)), sin_el_[l]};
      const Eigen::Vector3f d = R * dirs[l];
      pk.valid[l] = true;
      pk.ox[l] = o.x(), pk.oy[l] = o.y(), pk.oz[l] = o.z();
      pk.dx[l] = d.x(), pk.dy[l] = d.y(), pk.dz[l] = d.z();
      pk.tmax[l] = tmax;
    }
    world_.cast16(pk);
    for (int l = 0; l < 16; ++l) {
      out.range_m[l] = 0.0f;  // no return
      out.reflectivity[l] = 0;
      if (pk.distance[l] < 0.f) continue;
      // Noise and dropout drawn for returns only, in firing order: deterministic per seed.
      const double r = pk.distance[l] + opt_.range_noise_sigma * rng_.normal();
      if (opt_.dropout > 0.0 && rng_.uniform() < opt_.dropout) continue;
      if (r < opt_.min_range || r > opt_.max_range) continue;
      out.range_m[l] = float(r);
      out.reflectivity[l] = opt_.reflectivity;
      ++returns_;
    }
  }
}

}  // namespace storey::tools::sim
