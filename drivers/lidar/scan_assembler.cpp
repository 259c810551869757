#include "drivers/lidar/scan_assembler.hpp"

#include <cmath>

namespace storey::drivers::lidar {

void RigidTransform::apply(float& x, float& y, float& z) const {
  // v' = q v q* + t, expanded (t2 = 2 q_vec x v; v' = v + w t2 + q_vec x t2).
  const float t2x = 2.f * (qy * z - qz * y);
  const float t2y = 2.f * (qz * x - qx * z);
  const float t2z = 2.f * (qx * y - qy * x);
  const float nx = x + qw * t2x + (qy * t2z - qz * t2y);
  const float ny = y + qw * t2y + (qz * t2x - qx * t2z);
  const float nz = z + qw * t2z + (qx * t2y - qy * t2x);
  x = nx + tx;
  y = ny + ty;
  z = nz + tz;
}

RigidTransform RigidTransform::inverse() const {
  RigidTransform r;
  r.qw = qw;
  r.qx = -qx;
  r.qy = -qy;
  r.qz = -qz;
  r.tx = r.ty = r.tz = 0.f;
  float x = -tx, y = -ty, z = -tz;
  r.apply(x, y, z);
  r.tx = x;
  r.ty = y;
  r.tz = z;
  return r;
}

RigidTransform RigidTransform::operator*(const RigidTransform& o) const {
  RigidTransform r;
  r.qw = qw * o.qw - qx * o.qx - qy * o.qy - qz * o.qz;
  r.qx = qw * o.qx + qx * o.qw + qy * o.qz - qz * o.qy;
  r.qy = qw * o.qy - qx * o.qz + qy * o.qw + qz * o.qx;
  r.qz = qw * o.qz + qx * o.qy - qy * o.qx + qz * o.qw;
  float x = o.tx, y = o.ty, z = o.tz;
  apply(x, y, z);
  r.tx = x;
  r.ty = y;
  r.tz = z;
  return r;
}

ScanAssembler::ScanAssembler(Options opt, ScanSink* sink) : opt_(opt), sink_(sink) {
  scan_.points.reserve(opt_.max_points);
}

void ScanAssembler::push(const LidarPoint& p, uint64_t t_ns) {
  if (scan_.points.empty()) scan_.start_ns = t_ns;
  if (scan_.points.size() >= opt_.max_points) {
    ++overflowed_;
    return;
  }
  // Times relative to the scan start (int32 ns covers 2.1 s, far beyond a scan).
  LidarPoint q = p;
  q.time_offset_ns = static_cast<int32_t>(static_cast<int64_t>(t_ns - scan_.start_ns));
  scan_.points.push_back(q);  // capacity reserved: no allocation
  if (t_ns > scan_.end_ns) scan_.end_ns = t_ns;
}

void ScanAssembler::add_packet(std::span<const LidarPoint> points, uint64_t packet_time_ns,
                               uint32_t frame_id) {
  if (opt_.mode == Mode::frame_counter) {
    if (!scan_.points.empty() && frame_id != scan_.frame_id) emit();
    scan_.frame_id = frame_id;
  }
  bool counted = false;
  for (const LidarPoint& p : points) {
    const uint64_t t = packet_time_ns + static_cast<int64_t>(p.time_offset_ns);
    if (opt_.mode == Mode::rotation) {
      // Velodyne azimuth: clockwise from +y, a = atan2(x, y).
      float az = std::atan2(p.x, p.y) * (180.f / 3.14159265f) - opt_.cut_azimuth_deg;
      az = std::fmod(az + 720.f, 360.f);
      // A drop of more than half a turn is the wrap past the cut angle.
      if (last_rel_az_ >= 0.f && az + 180.f < last_rel_az_ && !scan_.points.empty()) emit();
      last_rel_az_ = az;
    } else if (opt_.mode == Mode::time_window) {
      const uint64_t w = t / opt_.window_ns;
      if (window_set_ && w != window_ && !scan_.points.empty()) emit();
      window_ = w;
      window_set_ = true;
    }
    if (!counted) {
      ++scan_.packets;
      counted = true;
    }
    push(p, t);
  }
}

void ScanAssembler::flush() {
  if (!scan_.points.empty()) emit();
}

void ScanAssembler::emit() {
  scan_.index = next_index_++;
  scan_.deskewed = false;
  if (poses_ != nullptr) {
    RigidTransform end_pose;
    if (poses_->pose_at(scan_.end_ns, end_pose)) {
      const RigidTransform end_inv = end_pose.inverse();
      for (LidarPoint& p : scan_.points) {
        RigidTransform pose;
        if (!poses_->pose_at(scan_.start_ns + static_cast<uint64_t>(p.time_offset_ns), pose)) {
          ++without_pose_;
          continue;
        }
        (end_inv * pose).apply(p.x, p.y, p.z);
      }
      scan_.deskewed = true;
    } else {
      without_pose_ += scan_.points.size();
    }
  }
  if (sink_ != nullptr) sink_->on_scan(scan_);
  scan_.points.clear();
  scan_.packets = 0;
  scan_.start_ns = scan_.end_ns = 0;
}

}  // namespace storey::drivers::lidar
