#include "tools/sim/hil_runner.hpp"

#include <time.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <stdexcept>

#include "drivers/lidar/mid360.hpp"
#include "drivers/lidar/vlp16.hpp"

namespace storey::tools::sim {

namespace lidar = storey::drivers::lidar;
namespace go2 = storey::drivers::go2;

namespace {

int64_t now_ns(clockid_t c) {
  timespec ts;
  clock_gettime(c, &ts);
  return int64_t(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

[[noreturn]] void fail(const std::string& why) {
  throw std::runtime_error(why);
}

// "0.0.0.0" (bind to any) is not a destination; on one machine it means loopback.
std::string local_destination(const std::string& a) {
  return a.empty() || a == "0.0.0.0" ? "127.0.0.1" : a;
}

uint16_t port(int p, const char* key) {
  if (p < 0 || p > 65535) fail(std::string(key) + ": port " + std::to_string(p) + " out of range");
  return uint16_t(p);
}

}  // namespace

HilRunner::HilRunner(const Scene& scene, const config::Parameters& params,
                     const HilOptions& options)
    : params_(params), opt_(options), history_(kHistory) {
  if (!(opt_.rate > 0.0) || !std::isfinite(opt_.rate)) fail("--rate must be > 0");
  if (!(opt_.duration >= 0.0)) fail("--duration must be >= 0");
  if (!(opt_.step > 0.0 && opt_.step <= 0.01)) fail("hil: step must be within (0, 10 ms]");
  if (!(opt_.state_rate_hz > 0.0) || !(opt_.command_timeout_s > 0.0) || !(opt_.imu_rate_hz > 0.0))
    fail("hil: state rate, command timeout and IMU rate must be > 0");
  const std::optional<StartPose> start = opt_.start ? opt_.start : scene.start;
  if (!start) fail("scene '" + scene.name + "' has no start pose: give --start X,Y,Z,YAW_DEG");

  caster_ = std::make_unique<RayCaster>(scene.mesh);
  RobotOptions ro;
  ro.physics_rate = 1.0 / opt_.step;  // one physics step per loop step: no extrapolation
  ro.seed = opt_.seed * 0x9E3779B97F4A7C15ULL + 1;
  robot_ = std::make_unique<RobotModel>(*caster_, *start, ro);

  // Sensor mount: config gives it in the Go2 body frame (origin at the body centre); the sim's
  // body frame has its origin on the ground, body_height below.
  const config::SensorConfig& sc = params_.sensor;
  const Eigen::Matrix3d Rm = (Eigen::AngleAxisd(sc.mounting_rpy_rad[2], Eigen::Vector3d::UnitZ()) *
                              Eigen::AngleAxisd(sc.mounting_rpy_rad[1], Eigen::Vector3d::UnitY()) *
                              Eigen::AngleAxisd(sc.mounting_rpy_rad[0], Eigen::Vector3d::UnitX()))
                                 .toRotationMatrix();
  lidar_opt_.mount = Eigen::Isometry3d::Identity();
  lidar_opt_.mount.linear() = Rm;
  lidar_opt_.mount.translation() = Eigen::Vector3d(sc.mounting_xyz_m[0], sc.mounting_xyz_m[1],
                                                   sc.mounting_xyz_m[2] + opt_.body_height);
  lidar_opt_.range_noise_sigma = opt_.range_noise_sigma;
  lidar_opt_.dropout = opt_.dropout;
  lidar_opt_.rotation_hz = sc.scan_rate_hz;
  lidar_opt_.seed = opt_.seed * 0x9E3779B97F4A7C15ULL + 2;
  const bool vlp = sc.type == config::SensorType::kVlp16;
  lidar_opt_.min_range = vlp ? 0.3 : 0.1;  // the sensors' own blind zones
  try {
    if (vlp) {
      vlp_ = std::make_unique<HilVlp16Source>(*caster_, lidar_opt_);
    } else {
      mid_ = std::make_unique<HilMid360Source>(*caster_, lidar_opt_, opt_.step);
    }
  } catch (const std::exception& e) {
    fail(std::string("sensor: ") + e.what());
  }

  // LiDAR datagrams: from the sensor's address (the firmware filters on it) to the host.
  // VLP-16 sends from an ephemeral port: its real source port equals the host's data port, and
  // binding that on loopback would collide with (or steal from) the firmware's socket.
  HilPacketSender::Options so;
  so.source_address = sc.sensor_address.empty() ? "127.0.0.1" : sc.sensor_address;
  so.source_port = vlp ? 0 : lidar::kMid360PointPort;
  so.dest_address = local_destination(sc.host_address);
  so.dest_port = port(sc.data_port, "sensor.data_port");
  if (so.dest_port == 0) fail("sensor.data_port: 0 is not a destination");
  if (std::string e = data_.open(so); !e.empty()) fail("sensor.sensor_address: " + e);
  if (!data_.warning().empty()) warnings_.push_back(data_.warning());
  dest_ = so.dest_address + ":" + std::to_string(so.dest_port);
  if (!vlp && sc.imu_port != 0) {
    so.source_port = lidar::kMid360ImuPort;
    so.dest_port = port(sc.imu_port, "sensor.imu_port");
    if (std::string e = imu_.open(so); !e.empty()) fail("sensor.imu_port: " + e);
    if (!imu_.warning().empty()) warnings_.push_back(imu_.warning());
    imu_dest_ = so.dest_address + ":" + std::to_string(so.dest_port);
  }

  // The robot's side of the link.
  HilRobotBridgeOptions bo;
  bo.body_height = opt_.body_height;
  bo.command_timeout_ns = int64_t(std::llround(opt_.command_timeout_s * 1e9));
  bo.standin.state_period_ns = int64_t(std::llround(1e9 / opt_.state_rate_hz));
  bo.standin.heartbeat_period_ns =
      int64_t(std::llround(std::max(0.01, params_.link.heartbeat_period_s) * 1e9));
  const config::LinkConfig& lc = params_.link;
  switch (lc.transport) {
    case config::LinkTransport::kUdp:
      bo.standin.transport = go2::StandinTransport::udp;
      // The robot listens where the firmware sends commands, and publishes where it listens.
      bo.standin.local = {lc.udp.robot_address, port(lc.udp.robot_port, "link.udp.robot_port")};
      bo.standin.host = {local_destination(lc.udp.local_address),
                         port(lc.udp.local_port, "link.udp.local_port")};
      link_desc_ = "udp: robot listens on " + lc.udp.robot_address + ":" +
                   std::to_string(lc.udp.robot_port) + ", state to " + bo.standin.host.address +
                   ":" + (lc.udp.local_port ? std::to_string(lc.udp.local_port) : "<sender>");
      break;
    case config::LinkTransport::kDds:
      bo.standin.transport = go2::StandinTransport::dds;
      bo.standin.dds.domain_id = uint32_t(lc.dds.domain_id);
      bo.standin.dds.interface = lc.dds.interface;
      bo.standin.dds.allow_multicast = lc.dds.allow_multicast;
      bo.standin.dds.peers = lc.dds.peers;
      link_desc_ = "dds: domain " + std::to_string(lc.dds.domain_id) +
                   (lc.dds.interface.empty() ? "" : " on " + lc.dds.interface) +
                   ", rt/sportmodestate + rt/lowstate, serving rt/api/sport/request";
      break;
    case config::LinkTransport::kCan:
      fail(
          "link.transport: can (SocketCAN) is not served by storey-sim; use udp or dds for "
          "hardware-in-the-loop");
    case config::LinkTransport::kSim:
      fail(
          "link.transport: sim is the in-process simulator; hardware-in-the-loop needs udp or "
          "dds (see config/hil.yaml)");
  }
  bridge_ = std::make_unique<HilRobotBridge>(bo, now_ns(CLOCK_MONOTONIC));
  if (!bridge_->ok()) fail(std::string("link: ") + bridge_->error());

  pose_fn_ = [this](double t) { return pose_at(t); };
  emit_data_ = [this](std::span<const uint8_t> d) { data_.queue(d); };
}

HilRunner::~HilRunner() = default;

std::string HilRunner::describe() const {
  std::string s = std::string(vlp_ ? "VLP-16" : "Mid-360") + " packets from " +
                  params_.sensor.sensor_address + ":" + std::to_string(data_.bound_port()) +
                  " to " + dest_;
  if (!imu_dest_.empty()) s += ", IMU to " + imu_dest_;
  s += "; link " + link_desc_;
  return s;
}

void HilRunner::record_pose(double t) {
  const Eigen::Isometry3d T = robot_->state().body_pose();
  Stamped& e = history_[history_head_];
  e.t = t;
  e.p = T.translation();
  e.q = Eigen::Quaterniond(T.linear());
  history_head_ = (history_head_ + 1) % kHistory;
  history_size_ = std::min(history_size_ + 1, kHistory);
}

Eigen::Isometry3d HilRunner::pose_at(double t) const {
  // Newest first: find the first entry at or before t, interpolate toward its successor.
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  const Stamped* later = nullptr;
  for (std::size_t i = 0; i < history_size_; ++i) {
    const Stamped& e = history_[(history_head_ + kHistory - 1 - i) % kHistory];
    if (e.t <= t || i + 1 == history_size_) {
      if (later == nullptr || e.t > t) {  // beyond either end: clamp
        T.translation() = e.p;
        T.linear() = e.q.toRotationMatrix();
        return T;
      }
      const double u = later->t > e.t ? (t - e.t) / (later->t - e.t) : 0.0;
      T.translation() = e.p + u * (later->p - e.p);
      T.linear() = e.q.slerp(u, later->q).toRotationMatrix();
      return T;
    }
    later = &e;
  }
  return T;
}

void HilRunner::send_imu(double t) {
  // Mid-360 built-in IMU (200 Hz): angular rate and specific force [g] in the sensor frame.
  while (next_imu_t_ <= t + 1e-12) {
    const RobotState& s = robot_->state();
    const Eigen::Matrix3d Rb = s.body_pose().linear();
    const Eigen::Matrix3d Rs = lidar_opt_.mount.linear().transpose();
    const Eigen::Vector3d w = Rs * Eigen::Vector3d(0, 0, s.velocity.z());
    const Eigen::Vector3d f = Rs * (Rb.transpose() * Eigen::Vector3d(0, 0, 1.0));
    lidar::ImuSample imu;
    imu.timestamp_ns = uint64_t(sensor_epoch_ns_ + std::llround(next_imu_t_ * 1e9));
    for (int i = 0; i < 3; ++i) imu.gyro[i] = float(w[i]), imu.acc[i] = float(f[i]);
    lidar::Mid360PacketMeta meta;
    meta.timestamp_ns = imu.timestamp_ns;
    meta.udp_cnt = imu_cnt_++;
    meta.time_type = uint8_t(lidar::Mid360TimeType::ptp);
    uint8_t buf[lidar::kMid360HeaderSize + sizeof(lidar::Mid360Imu)];
    const std::size_t n = lidar::mid360_encode_imu(meta, imu, buf);
    if (n > 0) imu_.queue(std::span<const uint8_t>(buf, n));
    next_imu_t_ += 1.0 / opt_.imu_rate_hz;
  }
  imu_.flush();
}

void HilRunner::refresh_stats(int64_t wall_ns) {
  const RobotState& s = robot_->state();
  stats_.wall_time_s = double(wall_ns - wall_start_ns_) * 1e-9;
  stats_.lidar_packets = data_.counters().sent;
  stats_.lidar_returns = vlp_ ? vlp_->returns() : mid_->returns();
  stats_.imu_packets = imu_.counters().sent;
  stats_.send_errors = data_.counters().send_errors + data_.counters().overflow +
                       imu_.counters().send_errors + imu_.counters().overflow;
  stats_.velocity_commands = bridge_->velocity_commands();
  stats_.mode_commands = bridge_->mode_commands();
  stats_.heartbeats = bridge_->heartbeats();
  stats_.link_dropped = bridge_->dropped();
  stats_.command_timeouts = bridge_->timeouts();
  stats_.collisions = s.collisions;
  stats_.falls = s.falls;
  stats_.stuck_events = s.stuck_events;
  stats_.distance_m = s.distance;
}

void HilRunner::run(const std::atomic<bool>& stop,
                    const std::function<void(const HilStats&)>& progress) {
  // Clocks: simulated time 0 = now. Sensor stamps follow CLOCK_REALTIME (VLP-16: us past the
  // hour; Mid-360: PTP-like ns), the robot's stamps CLOCK_MONOTONIC (what the Go2 link carries);
  // both advance with simulated time, so at --rate 1 they are the real clocks.
  const double t0 = robot_->state().t;
  wall_start_ns_ = now_ns(CLOCK_MONOTONIC);
  const int64_t robot_epoch = wall_start_ns_ - int64_t(std::llround(t0 * 1e9));
  sensor_epoch_ns_ = now_ns(CLOCK_REALTIME) - int64_t(std::llround(t0 * 1e9));
  if (vlp_) vlp_->set_clock_epoch(sensor_epoch_ns_);
  if (mid_) mid_->set_clock_epoch(sensor_epoch_ns_);
  next_imu_t_ = t0;
  record_pose(t0);
  VelocityCommand cmd = bridge_->step(robot_->state(), robot_->odometry(), robot_epoch);
  const double wall_step_ns = opt_.step / opt_.rate * 1e9;
  int64_t next_progress = wall_start_ns_ + int64_t(opt_.progress_period_s * 1e9);
  for (uint64_t k = 1;; ++k) {
    if (stop.load(std::memory_order_relaxed)) break;
    const double t = t0 + double(k) * opt_.step;
    if (opt_.duration > 0.0 && t > t0 + opt_.duration + 1e-9) break;
    // 1. Physics with the command in force.
    robot_->step(opt_.step, cmd);
    record_pose(t);
    // 2. Sensor packets whose shots are all in the past.
    if (vlp_) vlp_->produce(t, pose_fn_, emit_data_);
    if (mid_) mid_->produce(t, pose_fn_, emit_data_);
    data_.flush();
    if (imu_.is_open()) send_imu(t);
    // 3. Robot state out, commands in (they act from the next step on).
    cmd = bridge_->step(robot_->state(), robot_->odometry(),
                        robot_epoch + int64_t(std::llround((t - t0) * 1e9)));
    stats_.steps = k;
    stats_.sim_time_s = t - t0;
    // 4. Pace: sleep to the step's absolute deadline (cyclictest style); late steps run on.
    const int64_t deadline = wall_start_ns_ + int64_t(std::llround(double(k) * wall_step_ns));
    const int64_t now = now_ns(CLOCK_MONOTONIC);
    if (now >= next_progress) {
      next_progress = now + int64_t(opt_.progress_period_s * 1e9);
      refresh_stats(now);
      if (progress) progress(stats_);
    }
    if (now > deadline) {
      ++stats_.late_steps;
      stats_.max_lag_s = std::max(stats_.max_lag_s, double(now - deadline) * 1e-9);
    } else {
      timespec ts{time_t(deadline / 1'000'000'000), long(deadline % 1'000'000'000)};
      while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
        if (stop.load(std::memory_order_relaxed)) break;
      }
    }
  }
  refresh_stats(now_ns(CLOCK_MONOTONIC));
}

}  // namespace storey::tools::sim
