#include "tools/sim/hil_mid360_source.hpp"

#include <cmath>
#include <stdexcept>

namespace storey::tools::sim {

namespace lidar = storey::drivers::lidar;
constexpr uint64_t kPerPacket = lidar::kMid360MaxPointsPerPacket;

HilMid360Source::HilMid360Source(const RayCaster& world, const HilLidarOptions& options,
                                 double slice)
    : opt_(options) {
  const double rate = opt_.mid360_points_per_second;
  if (!(rate > 0.0) || !(slice > 0.0) || !(opt_.rotation_hz > 0.0))
    throw std::runtime_error("hil mid360: need point rate, slice and frame rate > 0");
  shots_per_slice_ = uint64_t(std::llround(rate * slice));
  shots_per_frame_ = uint64_t(std::llround(rate / opt_.rotation_hz));
  if (shots_per_slice_ == 0 || std::abs(double(shots_per_slice_) - rate * slice) > 1e-6)
    throw std::runtime_error("hil mid360: point rate x step must be a whole number of shots");
  if (shots_per_frame_ < kPerPacket)
    throw std::runtime_error("hil mid360: frame rate too high for the point rate");
  LidarOptions lo;
  lo.type = LidarType::mid360;
  lo.mount = opt_.mount;
  lo.min_range = opt_.min_range;
  lo.max_range = opt_.max_range;
  lo.range_noise_sigma = opt_.range_noise_sigma;
  lo.dropout = opt_.dropout;
  lo.scan_period = slice;
  lo.mid360_points_per_second = rate;
  lo.seed = opt_.seed;
  model_ = std::make_unique<LidarModel>(world, lo);  // validates ranges, noise, dropout
}

int HilMid360Source::produce(double t, const PoseAtTime& pose, const HilEmit& emit) {
  const double rate = opt_.mid360_points_per_second;
  int n = 0;
  while (double(shot_ + shots_per_slice_) / rate <= t + 1e-12) {
    const uint64_t base = shot_;
    model_->scan(double(base) / rate, pose, scan_);
    for (std::size_t k = 0; k < scan_.size(); ++k) {
      // The model's shot times are i / rate from the slice start: recover the shot index.
      const uint64_t g = base + uint64_t(std::llround(double(scan_.times[k]) * rate));
      while (g >= (packet_ + 1) * kPerPacket) {
        emit_packet(emit);
        ++n;
      }
      lidar::LidarPoint& p = slots_[g - packet_ * kPerPacket];
      const Eigen::Vector3f& s = scan_.points_sensor[k];
      p.x = s.x(), p.y = s.y(), p.z = s.z();
      p.intensity = opt_.reflectivity;
      p.tag = 0;
      ++returns_;
    }
    shot_ += shots_per_slice_;
    while (shot_ >= (packet_ + 1) * kPerPacket) {
      emit_packet(emit);
      ++n;
    }
  }
  return n;
}

void HilMid360Source::emit_packet(const HilEmit& emit) {
  const double rate = opt_.mid360_points_per_second;
  const uint64_t first = packet_ * kPerPacket;
  const uint64_t frame = first / shots_per_frame_;
  // udp_cnt restarts at the first packet that starts inside a new frame.
  const uint64_t frame_first_packet = (frame * shots_per_frame_ + kPerPacket - 1) / kPerPacket;
  lidar::Mid360PacketMeta meta;
  meta.timestamp_ns = uint64_t(opt_.clock_epoch_ns + std::llround(double(first) / rate * 1e9));
  meta.time_interval = uint16_t(std::llround(double(kPerPacket - 1) / rate * 1e7));
  meta.udp_cnt = uint16_t(packet_ - frame_first_packet);
  meta.frame_cnt = uint8_t(frame & 0xff);
  // Stamps follow the host's clock (as a PTP-synchronised unit would).
  meta.time_type = uint8_t(lidar::Mid360TimeType::ptp);
  meta.fill_crc = true;
  const std::size_t bytes = lidar::mid360_encode_points(meta, lidar::Mid360DataType::cartesian_high,
                                                        slots_, std::span<uint8_t>(buf_));
  if (bytes > 0 && emit) emit(std::span<const uint8_t>(buf_.data(), bytes));
  slots_.fill(lidar::LidarPoint{});
  ++packet_;
}

}  // namespace storey::tools::sim
