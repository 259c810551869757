#include "tools/sim/robot_model.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace storey::tools::sim {

namespace {
double approach(double v, double target, double max_delta) {
  return v + std::clamp(target - v, -max_delta, max_delta);
}
constexpr double kFallDepth = 20.0;  // [m] how far below the feet support is searched
}  // namespace

Eigen::Isometry3d RobotState::body_pose() const {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = position;
  T.linear() = (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
                Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  return T;
}

RobotModel::RobotModel(const RayCaster& world, const StartPose& start, const RobotOptions& options)
    : world_(world), opt_(options), rng_(options.seed) {
  if (!(opt_.physics_rate > 0.0 && opt_.step_height > 0.0 && opt_.length > 0.0 &&
        opt_.width > 0.0 && opt_.height > opt_.step_height))
    throw std::runtime_error("robot model: invalid options");
  s_.position = {start.x, start.y, start.z};
  s_.yaw = start.yaw;
  // Settle on the surface under the start point (searching from body height down).
  const Probe p = probe(start.x, start.y, start.z + 0.5);
  if (p.hit) s_.position.z() = p.z;
  attitude(s_.position.x(), s_.position.y(), s_.yaw, s_.position.z(), &s_.pitch, &s_.roll);
  odom_.position = s_.position;
  odom_.yaw = s_.yaw;
  stuck_anchor_ = s_.position;
}

// Highest surface under (x, y) below z_ref + body height.
RobotModel::Probe RobotModel::probe(double x, double y, double z_ref) const {
  Probe p;
  RayHit h;
  const Eigen::Vector3f o(float(x), float(y), float(z_ref + opt_.height));
  if (world_.cast(o, Eigen::Vector3f(0, 0, -1), float(opt_.height + kFallDepth), &h)) {
    p.hit = true;
    p.z = o.z() - h.distance;
    p.tilt = std::acos(std::min(1.0f, std::abs(h.normal.z())));
  }
  return p;
}

// A legged trunk follows the mean plane of the ground under its feet, not the ground under four
// points: pitch and roll come from a least-squares plane z = a + b x + c y (body-yaw frame)
// through probes on a 9 x 3 grid under the footprint. Four edge probes made the attitude jump by
// a full riser whenever one crossed a stair nosing (15 <-> 29 deg pitch on a 0.29 m run, 28 deg
// roll when one side probe was a tread ahead), which wedged any slightly skewed climb.
void RobotModel::attitude(double x, double y, double yaw, double z, double* pitch,
                          double* roll) const {
  const double c = std::cos(yaw), s = std::sin(yaw);
  const double hx = opt_.length / 2 - 0.05, hy = opt_.width / 2;
  const double reach = opt_.step_height + hx * std::tan(opt_.max_slope_deg * M_PI / 180.0);
  constexpr int kNx = 9, kNy = 3;
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  Eigen::Vector3d r = Eigen::Vector3d::Zero();
  int n = 0;
  for (int i = 0; i < kNx; ++i)
    for (int j = 0; j < kNy; ++j) {
      const double bx = -hx + 2 * hx * i / (kNx - 1), by = -hy + 2 * hy * j / (kNy - 1);
      const Probe p = probe(x + c * bx - s * by, y + s * bx + c * by, z);
      if (!p.hit || std::abs(p.z - z) > reach) continue;
      const Eigen::Vector3d row(1.0, bx, by);
      A += row * row.transpose();
      r += row * (p.z - z);
      ++n;
    }
  *pitch = 0.0, *roll = 0.0;
  if (n < 3 || std::abs(A.determinant()) < 1e-9) return;  // too little support seen: level
  const Eigen::Vector3d abc = A.ldlt().solve(r);
  *pitch = -std::atan(abc.y());
  *roll = std::atan(abc.z());
}

// Segments through the body box between step height (+2 cm) and the body top: its four edges,
// both diagonals and both centre lines at three heights. Anything crossing one is a collision.
bool RobotModel::body_collides(const Eigen::Isometry3d& body) const {
  const double hx = opt_.length / 2, hy = opt_.width / 2;
  const double z0 = opt_.step_height + 0.02, z1 = opt_.height - 0.01;
  const double zs[3] = {z0, 0.5 * (z0 + z1), z1};
  const Eigen::Vector2d seg[8][2] = {{{hx, -hy}, {hx, hy}},  {{-hx, -hy}, {-hx, hy}},
                                     {{-hx, hy}, {hx, hy}},  {{-hx, -hy}, {hx, -hy}},
                                     {{-hx, -hy}, {hx, hy}}, {{-hx, hy}, {hx, -hy}},
                                     {{-hx, 0}, {hx, 0}},    {{0, -hy}, {0, hy}}};
  for (double z : zs)
    for (const auto& sg : seg) {
      const Eigen::Vector3d a = body * Eigen::Vector3d(sg[0].x(), sg[0].y(), z);
      const Eigen::Vector3d b = body * Eigen::Vector3d(sg[1].x(), sg[1].y(), z);
      if (world_.blocked(a.cast<float>(), b.cast<float>())) return true;
    }
  return false;
}

void RobotModel::physics_step(const VelocityCommand& cmd_in) {
  const double h = physics_step();
  // Bad commands (NaN) are treated as stop.
  VelocityCommand cmd = cmd_in;
  if (!std::isfinite(cmd.vx) || !std::isfinite(cmd.vy) || !std::isfinite(cmd.yaw_rate)) cmd = {};
  const double sp = std::hypot(cmd.vx, cmd.vy);
  if (sp > opt_.max_speed) cmd.vx *= opt_.max_speed / sp, cmd.vy *= opt_.max_speed / sp;
  cmd.yaw_rate = std::clamp(cmd.yaw_rate, -opt_.max_yaw_rate, opt_.max_yaw_rate);
  Eigen::Vector3d v = s_.velocity;
  v.x() = approach(v.x(), cmd.vx, opt_.max_accel * h);
  v.y() = approach(v.y(), cmd.vy, opt_.max_accel * h);
  v.z() = approach(v.z(), cmd.yaw_rate, opt_.max_yaw_accel * h);

  const double yaw_mid = s_.yaw + 0.5 * v.z() * h;
  const double c = std::cos(yaw_mid), s = std::sin(yaw_mid);
  const double nx = s_.position.x() + (c * v.x() - s * v.y()) * h;
  const double ny = s_.position.y() + (s * v.x() + c * v.y()) * h;
  const double nyaw = s_.yaw + v.z() * h;

  bool blocked = false;
  const Probe centre = probe(nx, ny, s_.position.z());
  const double max_tilt = opt_.max_slope_deg * M_PI / 180.0;
  double nz = s_.position.z();
  bool fell = false;
  if (centre.hit && centre.z - s_.position.z() > opt_.step_height) {
    blocked = true;  // a step too high (or a wall foot) under the body centre
  } else if (centre.hit && centre.z - s_.position.z() >= -opt_.step_height) {
    blocked = centre.tilt > max_tilt + 1e-6;  // too steep to stand on
    nz = centre.z;
  } else {
    fell = true;  // support vanished beyond the step height: ledge
    nz = centre.hit ? centre.z : s_.position.z() - kFallDepth;
  }
  double pitch = s_.pitch, roll = s_.roll;
  double fx = nx, fy = ny;
  if (!blocked) {
    attitude(nx, ny, nyaw, nz, &pitch, &roll);
    RobotState trial = s_;
    trial.position = {nx, ny, nz};
    trial.yaw = nyaw, trial.pitch = pitch, trial.roll = roll;
    if (fell) {
      // The body tips over the edge: it lands clear of the ledge, pushed on along its motion
      // (or away from its heading when standing) until the box no longer meets the world.
      const double mx = nx - s_.position.x(), my = ny - s_.position.y();
      const double ml = std::hypot(mx, my);
      const double ux = ml > 1e-9 ? mx / ml : std::cos(nyaw),
                   uy = ml > 1e-9 ? my / ml : std::sin(nyaw);
      for (int k = 0; k <= 20 && body_collides(trial.body_pose()); ++k) {
        fx = nx + ux * 0.05 * k, fy = ny + uy * 0.05 * k;
        const Probe p = probe(fx, fy, nz + opt_.step_height);
        trial.position = {fx, fy, p.hit ? p.z : nz};
      }
      nz = trial.position.z();
      attitude(fx, fy, nyaw, nz, &pitch, &roll);
    } else {
      blocked = body_collides(trial.body_pose());
    }
  }
  if (blocked) {
    if (!s_.blocked) ++s_.collisions;
    s_.blocked = true;
    s_.velocity.setZero();
  } else {
    if (fell) ++s_.falls;
    const Eigen::Vector3d np(fx, fy, nz);
    s_.distance += (np - s_.position).norm();
    if ((np - s_.position).head<2>().norm() > kWalkingSpeed * h) s_.walking_s += h;
    s_.position = np;
    s_.yaw = std::remainder(nyaw, 2.0 * M_PI);
    s_.pitch = pitch, s_.roll = roll;
    s_.velocity = v;
    s_.blocked = false;
  }
  ++steps_;
  s_.t = double(steps_) * h;

  // Odometry: integrate the measured body velocity (scale error, noise, yaw drift).
  Eigen::Vector3d vm = s_.velocity;
  vm.x() = vm.x() * (1.0 + opt_.odom_scale_error);
  vm.y() = vm.y() * (1.0 + opt_.odom_scale_error);
  vm.z() += opt_.odom_yaw_rate_bias;
  if (opt_.odom_speed_noise > 0.0) {
    vm.x() += opt_.odom_speed_noise * rng_.normal();
    vm.y() += opt_.odom_speed_noise * rng_.normal();
  }
  if (opt_.odom_yaw_rate_noise > 0.0) vm.z() += opt_.odom_yaw_rate_noise * rng_.normal();
  const double oc = std::cos(odom_.yaw), os = std::sin(odom_.yaw);
  odom_.position.x() += (oc * vm.x() - os * vm.y()) * h;
  odom_.position.y() += (os * vm.x() + oc * vm.y()) * h;
  odom_.position.z() = s_.position.z();  // leg odometry tracks height well
  odom_.yaw = std::remainder(odom_.yaw + vm.z() * h, 2.0 * M_PI);
  odom_.velocity = vm;
  odom_.t = s_.t;

  // Stuck: motion commanded for stuck_time without stuck_distance of progress.
  const bool commanded = sp > 0.05 || std::abs(cmd.yaw_rate) > 0.05;
  if (!commanded || (s_.position - stuck_anchor_).norm() > opt_.stuck_distance) {
    stuck_anchor_ = s_.position;
    stuck_since_ = s_.t;
    s_.stuck = false;
  } else if (s_.t - stuck_since_ >= opt_.stuck_time && !s_.stuck) {
    s_.stuck = true;
    ++s_.stuck_events;
  }
}

void RobotModel::step(double dt, const VelocityCommand& cmd) {
  if (!(dt >= 0.0) || !std::isfinite(dt)) return;
  const double h = physics_step();
  carry_ += dt;
  while (carry_ >= h - 1e-9) {
    physics_step(cmd);
    carry_ -= h;
  }
}

}  // namespace storey::tools::sim
