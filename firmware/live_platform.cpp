#include "firmware/live_platform.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <time.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace storey::firmware {

namespace lidar = drivers::lidar;
namespace go2 = drivers::go2;

namespace {

std::int64_t clock_ns(clockid_t id) {
  timespec ts;
  clock_gettime(id, &ts);
  return std::int64_t(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

lidar::RigidTransform to_rigid(const Eigen::Quaterniond& q, const Eigen::Vector3d& t) {
  lidar::RigidTransform r;
  r.qw = float(q.w()), r.qx = float(q.x()), r.qy = float(q.y()), r.qz = float(q.z());
  r.tx = float(t.x()), r.ty = float(t.y()), r.tz = float(t.z());
  return r;
}

}  // namespace

// Sensor pose at a point's time for the ScanAssembler: the body pose interpolated from a local
// copy of the pose history, composed with the configured mounting (body frame: origin at the body
// centre, as the Go2 reports its position). Queries come in time order; consecutive points within
// 20 us share one pose (at 1 m/s and 1 rad/s that is 20 um and 0.6 mm at 30 m).
class LivePlatform::Deskew final : public lidar::PoseSource {
 public:
  Deskew(const PoseHistory& h, const config::SensorConfig& s, std::int64_t max_extrapolation_ns)
      : history_(h), max_extrapolation_ns_(max_extrapolation_ns) {
    const Eigen::Quaterniond qm =
        Eigen::AngleAxisd(s.mounting_rpy_rad[2], Eigen::Vector3d::UnitZ()) *
        Eigen::AngleAxisd(s.mounting_rpy_rad[1], Eigen::Vector3d::UnitY()) *
        Eigen::AngleAxisd(s.mounting_rpy_rad[0], Eigen::Vector3d::UnitX());
    mount_q_ = qm;
    mount_t_ = {s.mounting_xyz_m[0], s.mounting_xyz_m[1], s.mounting_xyz_m[2]};
  }

  bool pose_at(uint64_t time_ns, lidar::RigidTransform& out) const override {
    const std::int64_t t = std::int64_t(time_ns);
    if (have_cache_ && std::llabs(t - cache_t_) <= kShareNs) {
      out = cache_;
      return true;
    }
    // Newer states may have arrived since the copy was taken: refresh when asked past its end.
    if ((n_ == 0 || t > snap_[n_ - 1].t_ns) && history_.pushed() != copied_) refresh();
    StampedPose body;
    if (!PoseHistory::interpolate(snap_.data(), n_, t, max_extrapolation_ns_, body, &hint_))
      return false;
    cache_ = to_rigid(body.q * mount_q_, body.p_m + body.q * mount_t_);
    cache_t_ = t;
    have_cache_ = true;
    out = cache_;
    return true;
  }

 private:
  static constexpr std::int64_t kShareNs = 20'000;
  void refresh() const {
    copied_ = history_.pushed();
    n_ = history_.snapshot(snap_);
    hint_ = 0;
    have_cache_ = false;
  }
  const PoseHistory& history_;
  std::int64_t max_extrapolation_ns_;
  Eigen::Quaterniond mount_q_;
  Eigen::Vector3d mount_t_;
  // Ingest-thread state (PoseSource::pose_at is const).
  mutable std::array<StampedPose, PoseHistory::kCapacity> snap_;
  mutable std::size_t n_ = 0, hint_ = 0;
  mutable std::uint64_t copied_ = ~0ull;
  mutable lidar::RigidTransform cache_;
  mutable std::int64_t cache_t_ = 0;
  mutable bool have_cache_ = false;
};

// Assembled, deskewed scans (sensor frame at the scan's end) -> world frame into the staged
// buffer, filtered by the sensor's range limits. The buffer's capacity is reserved once.
class LivePlatform::Sink final : public lidar::ScanSink {
 public:
  Sink(const Deskew& deskew, const config::SensorConfig& s, std::size_t reserve)
      : deskew_(deskew),
        min2_(float(s.min_range_m * s.min_range_m)),
        max2_(float(s.max_range_m * s.max_range_m)) {
    staged.points_m.reserve(reserve);
  }

  void on_scan(const lidar::Scan& scan) override {
    lidar::RigidTransform end;
    if (!scan.deskewed || !deskew_.pose_at(scan.end_ns, end)) {
      ++without_pose;
      return;
    }
    staged.clear();
    staged.stamp_s = double(scan.end_ns) * 1e-9;
    staged.origin_m = {end.tx, end.ty, end.tz};
    const std::size_t cap = staged.points_m.capacity();
    for (const lidar::LidarPoint& p : scan.points) {
      const float r2 = p.x * p.x + p.y * p.y + p.z * p.z;
      if (!(r2 >= min2_ && r2 <= max2_)) {  // also false for NaN
        ++out_of_range;
        continue;
      }
      if (staged.points_m.size() == cap) {  // never grow: count instead
        ++overflowed;
        continue;
      }
      float x = p.x, y = p.y, z = p.z;
      end.apply(x, y, z);
      staged.points_m.emplace_back(x, y, z);
    }
    ready = true;
  }

  ScanBuffer staged;
  bool ready = false;
  std::uint64_t without_pose = 0, out_of_range = 0, overflowed = 0;

 private:
  const Deskew& deskew_;
  float min2_, max2_;
};

LivePlatform::LivePlatform(const LivePlatformOptions& options, std::unique_ptr<go2::RobotLink> link,
                           const rt::Clock& clock)
    : opt_(options), link_(std::move(link)), clock_(clock), chunks_(options.chunk_queue) {
  const config::SensorConfig& s = opt_.params.sensor;
  const bool mid360 = s.type == config::SensorType::kMid360;
  lidar::UdpReceiver::Options ro;
  ro.sensor = mid360 ? lidar::SensorModel::mid360 : lidar::SensorModel::vlp16;
  ro.bind_address = s.host_address;
  ro.port = uint16_t(opt_.data_port >= 0 ? opt_.data_port : s.data_port);
  if (!s.sensor_address.empty()) {
    in_addr a{};
    if (inet_pton(AF_INET, s.sensor_address.c_str(), &a) == 1) ro.source_address = ntohl(a.s_addr);
  }
  ro.receive_buffer_bytes = s.rcvbuf_bytes;
  receiver_ = std::make_unique<lidar::UdpReceiver>(ro, chunks_);
  if (opt_.record_queue > 0) {
    record_ = std::make_unique<rt::SpscQueue<lidar::RawDatagram>>(opt_.record_queue);
    receiver_->set_record_queue(record_.get());
  }
  deskew_ = std::make_unique<Deskew>(history_, s, std::llround(opt_.max_extrapolation_s * 1e9));
  // A VLP-16 scan is at most 1808 packets' worth of 384 returns at 20 Hz... in practice one
  // revolution: 754 packets/s / rate x 384. Reserve for 2x the nominal point rate per scan.
  const double pts_per_s = mid360 ? 200'000.0 : 754.0 * 384.0;
  const std::size_t reserve = std::size_t(2.0 * pts_per_s / std::max(1.0, s.scan_rate_hz)) + 1024;
  sink_ = std::make_unique<Sink>(*deskew_, s, reserve);
  lidar::ScanAssembler::Options ao;
  ao.mode = mid360 ? lidar::ScanAssembler::Mode::time_window : lidar::ScanAssembler::Mode::rotation;
  ao.window_ns = uint64_t(std::llround(1e9 / std::max(1.0, s.scan_rate_hz)));
  ao.max_points = reserve;
  assembler_ = std::make_unique<lidar::ScanAssembler>(ao, sink_.get());
  assembler_->set_pose_source(deskew_.get());
}

LivePlatform::~LivePlatform() {
  if (receiver_) receiver_->close();
}

lidar::UdpReceiver::OpenStatus LivePlatform::open() {
  lidar::UdpReceiver::OpenStatus st = receiver_->open();
  if (!st.ok) return st;
  lidar_fd_ = receiver_->fd();
  if (lidar_fd_ < 0) {
    st.ok = false;
    st.error = "lidar: cannot find the socket of port " + std::to_string(receiver_->bound_port());
  }
  return st;
}

// ---- ingest task
bool LivePlatform::take_scan(ScanBuffer& out) {
  bool polled = false;
  // CLOCK_REALTIME receive stamps -> the monotonic firmware timeline.
  const std::int64_t rt_minus_mono = clock_ns(CLOCK_REALTIME) - clock_ns(CLOCK_MONOTONIC);
  for (;;) {
    if (sink_->ready) {
      sink_->ready = false;
      std::swap(out.points_m, sink_->staged.points_m);  // both keep their reserved capacity
      out.stamp_s = sink_->staged.stamp_s;
      out.origin_m = sink_->staged.origin_m;
      bump(scans_);
      return true;
    }
    lidar::PointChunk* c = chunks_.front();
    if (c == nullptr) {
      if (polled) break;
      receiver_->poll(0);
      polled = true;
      continue;
    }
    int32_t last = 0;
    for (uint32_t i = 0; i < c->count; ++i) last = std::max(last, c->points[i].time_offset_ns);
    const std::int64_t t = std::int64_t(c->receive_time_ns) - rt_minus_mono - last;
    assembler_->add_packet({c->points.data(), c->count}, uint64_t(std::max<std::int64_t>(t, 0)),
                           c->frame_cnt);
    chunks_.pop();
  }
  out_of_range_.store(sink_->out_of_range, std::memory_order_relaxed);
  scans_without_pose_.store(sink_->without_pose, std::memory_order_relaxed);
  points_without_pose_.store(assembler_->points_without_pose(), std::memory_order_relaxed);
  overflowed_.store(assembler_->points_overflowed() + sink_->overflowed, std::memory_order_relaxed);
  return false;
}

// ---- control task
PoseSample LivePlatform::to_pose_sample(const go2::RobotState& s, double default_body_height_m,
                                        double stamp_s) {
  const Eigen::Quaterniond q(s.quaternion[0], s.quaternion[1], s.quaternion[2], s.quaternion[3]);
  const Eigen::Quaterniond qn = q.norm() > 1e-6 ? q.normalized() : Eigen::Quaterniond::Identity();
  const double h =
      s.body_height > 0.05f && s.body_height < 1.0f ? double(s.body_height) : default_body_height_m;
  const Eigen::Vector3d centre(s.position[0], s.position[1], s.position[2]);
  const Eigen::Vector3d foot = centre - qn * Eigen::Vector3d(0, 0, h);
  const Eigen::Vector3d fwd = qn * Eigen::Vector3d::UnitX();
  PoseSample p;
  p.stamp_s = stamp_s;
  p.x_m = foot.x(), p.y_m = foot.y(), p.z_m = foot.z();
  p.yaw_rad = std::atan2(fwd.y(), fwd.x());
  const double c = std::cos(p.yaw_rad), sn = std::sin(p.yaw_rad);
  p.vx_mps = c * s.velocity[0] + sn * s.velocity[1];  // odometry frame -> body frame
  p.vy_mps = -sn * s.velocity[0] + c * s.velocity[1];
  p.yaw_rate_rps = s.yaw_speed;
  return p;
}

bool LivePlatform::latest_pose(PoseSample& out) {
  const std::int64_t now = clock_.now_ns();
  link_->poll(now);
  if (link_->has_state()) {
    const go2::RobotState& s = link_->latest_state();
    if (s.rx_stamp_ns != last_rx_ns_) {
      last_rx_ns_ = s.rx_stamp_ns;
      bump(states_);
      // A state whose sample time did not advance carries no new odometry (a frozen estimator):
      // the pose keeps its old stamp and goes stale (DESIGN §3) while the link stays alive.
      if (s.stamp_ns > last_sample_ns_) {
        last_sample_ns_ = s.stamp_ns;
        pose_ = to_pose_sample(s, opt_.default_body_height_m, double(s.rx_stamp_ns) * 1e-9);
        have_pose_ = true;
        pose_out_.write(pose_);
        StampedPose sp;
        sp.t_ns = s.rx_stamp_ns;
        sp.p_m = {s.position[0], s.position[1], s.position[2]};
        sp.q =
            Eigen::Quaterniond(s.quaternion[0], s.quaternion[1], s.quaternion[2], s.quaternion[3]);
        if (sp.q.norm() > 1e-6) {
          sp.q.normalize();
          history_.push(sp);
        }
      } else {
        bump(frozen_);
        if (s.stamp_ns < last_sample_ns_ - 1'000'000'000) last_sample_ns_ = s.stamp_ns;  // restart
      }
    }
  }
  if (!have_pose_) return false;
  out = pose_;
  return true;
}

void LivePlatform::send_command(const VelocityCommand& cmd) {
  go2::VelocityCommand c;
  c.stamp_ns = std::llround(cmd.stamp_s * 1e9);
  c.vx = float(cmd.vx_mps);
  c.vy = float(cmd.vy_mps);
  c.yaw_rate = float(cmd.yaw_rate_rps);
  // The link refuses (and counts) a command older than link.max_command_age_s at this instant.
  const go2::LinkStatus st = link_->send_velocity(c, clock_.now_ns());
  bump(st == go2::LinkStatus::ok ? sent_ : refused_);
}

LinkHealth LivePlatform::link() {
  const std::int64_t now = clock_.now_ns();
  const go2::LinkHealth h = link_->health(now);
  LinkHealth out;
  out.connected = !h.link_lost;
  out.last_state_s = h.last_state_age_ns >= 0 ? double(now - h.last_state_age_ns) * 1e-9 : -1;
  return out;
}

bool LivePlatform::command_stop() {
  const std::int64_t now = clock_.now_ns();
  go2::VelocityCommand zero;
  zero.stamp_ns = now;
  const bool a = link_->send_velocity(zero, now) == go2::LinkStatus::ok;
  go2::ModeCommand stop;
  stop.stamp_ns = now;
  stop.mode = go2::ModeRequest::stop;
  const bool b = link_->send_mode(stop, now) == go2::LinkStatus::ok;
  return a && b;
}

LiveCounters LivePlatform::counters() const {
  LiveCounters c;
  auto ld = [](const std::atomic<std::uint64_t>& a) { return a.load(std::memory_order_relaxed); };
  c.scans = ld(scans_);
  c.scans_without_pose = ld(scans_without_pose_);
  c.points_without_pose = ld(points_without_pose_);
  c.points_out_of_range = ld(out_of_range_);
  c.points_overflowed = ld(overflowed_);
  c.states = ld(states_);
  c.frozen_states = ld(frozen_);
  c.commands_sent = ld(sent_);
  c.commands_refused = ld(refused_);
  c.history_refused = history_.refused();
  return c;
}

}  // namespace storey::firmware
