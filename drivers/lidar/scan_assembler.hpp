#pragma once
// Groups decoded packets into scans: by rotation (VLP-16: a new scan when the azimuth wraps past
// the cut angle), by time window (Mid-360: 100 ms) or by the sensor's frame counter. Buffers are
// allocated once (capacity in Options) and reused; runs on the ingest thread without allocation.
// Deskewing (paper Section III-A assumes motion-compensated scans): each point is moved into the
// sensor frame at the scan's end time with the pose at its own time, from a PoseSource.
#include <cstdint>
#include <span>
#include <vector>

#include "drivers/lidar/point.hpp"

namespace storey::drivers::lidar {

// Rigid transform (sensor pose in a fixed frame): unit quaternion (w,x,y,z) and translation [m].
struct RigidTransform {
  float qw = 1.f, qx = 0.f, qy = 0.f, qz = 0.f;
  float tx = 0.f, ty = 0.f, tz = 0.f;
  void apply(float& x, float& y, float& z) const;
  RigidTransform inverse() const;
  RigidTransform operator*(const RigidTransform& o) const;  // this after o
};

// Pose history as seen by the assembler. The ingestion implements it over its pose mailbox /
// history and interpolates between samples; false = no pose for that time (point left as is and
// counted).
class PoseSource {
 public:
  virtual ~PoseSource() = default;
  virtual bool pose_at(uint64_t time_ns, RigidTransform& sensor_pose) const = 0;
};

struct Scan {
  std::vector<LidarPoint> points;  // time_offset_ns re-based to start_ns; packet order
  uint64_t start_ns = 0;           // first point's time
  uint64_t end_ns = 0;             // last point's time
  uint64_t index = 0;              // 0, 1, 2 ... in capture order (scan 0 may be partial)
  uint32_t packets = 0;
  uint32_t frame_id = 0;  // frame_counter mode: the sensor's frame counter
  bool deskewed = false;
};

class ScanSink {
 public:
  virtual ~ScanSink() = default;
  // Called on the assembler's thread; `scan` is reused after return (copy what you keep).
  virtual void on_scan(const Scan& scan) = 0;
};

class ScanAssembler {
 public:
  enum class Mode : uint8_t { rotation, time_window, frame_counter };
  struct Options {
    Mode mode = Mode::rotation;
    float cut_azimuth_deg = 0.f;       // rotation: scans start at this azimuth (Velodyne's)
    uint64_t window_ns = 100'000'000;  // time_window: 100 ms (Mid-360 at 10 Hz)
    std::size_t max_points = 400'000;  // per scan; more are dropped and counted
  };
  ScanAssembler(Options opt, ScanSink* sink);

  void set_pose_source(const PoseSource* poses) { poses_ = poses; }

  // Adds one packet's points (time_offset_ns relative to packet_time_ns). `frame_id` is used in
  // frame_counter mode only.
  void add_packet(std::span<const LidarPoint> points, uint64_t packet_time_ns,
                  uint32_t frame_id = 0);
  // Emits the scan in progress (end of a replay), if any point is in it.
  void flush();

  uint64_t scans_emitted() const { return next_index_; }
  uint64_t points_overflowed() const { return overflowed_; }
  uint64_t points_without_pose() const { return without_pose_; }

 private:
  void emit();
  void push(const LidarPoint& p, uint64_t t_ns);
  Options opt_;
  ScanSink* sink_;
  const PoseSource* poses_ = nullptr;
  Scan scan_;
  uint64_t next_index_ = 0;
  uint64_t overflowed_ = 0;
  uint64_t without_pose_ = 0;
  float last_rel_az_ = -1.f;  // rotation: previous point's azimuth past the cut [deg]
  uint64_t window_ = 0;
  bool window_set_ = false;
};

}  // namespace storey::drivers::lidar
