#include "firmware/control_law.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace storey::firmware {

double wrap_angle(double a) {
  a = std::remainder(a, 2.0 * M_PI);
  return a <= -M_PI ? a + 2.0 * M_PI : a;
}

VelocityCommand ControlLaw::track(const core::plan::TrajectorySample& ref, const PoseSample& pose,
                                  const VelocityCommand& prev, double dt_s,
                                  double yaw_scale) const {
  // World-frame planar velocity: feedforward + P on the position error.
  const double wx = ref.v_mps.x() + gains_.k_position * (ref.p_m.x() - pose.x_m);
  const double wy = ref.v_mps.y() + gains_.k_position * (ref.p_m.y() - pose.y_m);
  const double c = std::cos(pose.yaw_rad), s = std::sin(pose.yaw_rad);
  VelocityCommand cmd;
  cmd.vx_mps = c * wx + s * wy;  // rotate into the body frame
  cmd.vy_mps = -s * wx + c * wy;
  cmd.yaw_rate_rps =
      yaw_scale * (ref.yaw_rate_rps + gains_.k_yaw * wrap_angle(ref.yaw_rad - pose.yaw_rad));
  return limit(cmd, prev, dt_s);
}

VelocityCommand ControlLaw::limit(VelocityCommand cmd, const VelocityCommand& prev,
                                  double dt_s) const {
  if (!std::isfinite(cmd.vx_mps) || !std::isfinite(cmd.vy_mps) ||
      !std::isfinite(cmd.yaw_rate_rps)) {
    cmd.vx_mps = cmd.vy_mps = cmd.yaw_rate_rps = 0;  // never forward a NaN to the robot
  }
  // Speed and yaw-rate limits.
  const double v = std::hypot(cmd.vx_mps, cmd.vy_mps);
  if (v > robot_.max_speed_mps) {
    cmd.vx_mps *= robot_.max_speed_mps / v;
    cmd.vy_mps *= robot_.max_speed_mps / v;
  }
  cmd.yaw_rate_rps =
      std::clamp(cmd.yaw_rate_rps, -robot_.max_yaw_rate_rps, robot_.max_yaw_rate_rps);
  // Acceleration limits against the previous command.
  const double dv_max = robot_.max_accel_mps2 * dt_s;
  const double dvx = cmd.vx_mps - prev.vx_mps, dvy = cmd.vy_mps - prev.vy_mps;
  const double dv = std::hypot(dvx, dvy);
  if (dv > dv_max) {
    cmd.vx_mps = prev.vx_mps + dvx * dv_max / dv;
    cmd.vy_mps = prev.vy_mps + dvy * dv_max / dv;
  }
  const double dw_max = robot_.max_yaw_accel_rps2 * dt_s;
  cmd.yaw_rate_rps =
      std::clamp(cmd.yaw_rate_rps, prev.yaw_rate_rps - dw_max, prev.yaw_rate_rps + dw_max);
  return cmd;
}

void ControlLaw::turn_poses(const core::plan::TrajectorySample& ref, const PoseSample& pose,
                            std::vector<core::plan::BodyPose>& out) const {
  out.clear();
  const double dyaw = wrap_angle(ref.yaw_rad - pose.yaw_rad);
  if (!(std::abs(dyaw) >= kTurnMinRad) || !ref.p_m.allFinite()) return;
  const Eigen::Vector3d from = pose.position(), to = ref.p_m;
  const double ratio = gains_.k_position / std::max(gains_.k_yaw, 1e-3);
  const int n = int(std::ceil(std::abs(dyaw) / kTurnStepRad));
  for (int k = 1; k <= n; ++k) {
    const double f = double(k) / n, g = 1.0 - std::pow(1.0 - f, ratio);
    out.push_back(
        core::plan::BodyPose{from + g * (to - from), pose.yaw_rad + f * dyaw, 0.0, pose.stamp_s});
  }
}

void ControlLaw::slide_poses(const core::plan::TrajectorySample& ref, const PoseSample& pose,
                             std::vector<core::plan::BodyPose>& out) const {
  out.clear();
  const double dyaw = wrap_angle(ref.yaw_rad - pose.yaw_rad);
  const Eigen::Vector3d from = pose.position(), to = ref.p_m;
  const double d = (to - from).head<2>().norm();
  if (!(std::abs(dyaw) >= kTurnMinRad) || !(d <= kSlideMaxM) || !to.allFinite()) return;
  const int n = int(std::ceil(d / kSlideStepM));
  for (int k = 1; k <= n; ++k)
    out.push_back(core::plan::BodyPose{from + (double(k) / n) * (to - from), pose.yaw_rad, 0.0,
                                       pose.stamp_s});
  const int m = int(std::ceil(std::abs(dyaw) / kTurnStepRad));
  for (int k = 1; k <= m; ++k)
    out.push_back(
        core::plan::BodyPose{to, pose.yaw_rad + (double(k) / m) * dyaw, 0.0, pose.stamp_s});
}

size_t ControlLaw::max_swept_poses() {
  return size_t(std::ceil(kSlideMaxM / kSlideStepM)) + size_t(std::ceil(M_PI / kTurnStepRad)) + 2;
}

namespace {
// 1 up to full_m, falling linearly to 0 at zero_m; 0 for a non-finite distance.
double ramp_down(double d, double full_m, double zero_m) {
  const double g = std::clamp((zero_m - d) / (zero_m - full_m), 0.0, 1.0);
  return std::isfinite(g) ? g : 0.0;
}
}  // namespace

double ControlLaw::on_reference(const core::plan::TrajectorySample& ref,
                                const PoseSample& pose) const {
  return ramp_down(braking_gap(ref, pose), gains_.on_reference_full_m, gains_.on_reference_zero_m);
}

double ControlLaw::on_path(const core::plan::BsplineTrajectory& t, double from_s, double to_s,
                           const PoseSample& pose) const {
  if (t.empty()) return 0.0;
  const Eigen::Vector2d rest = rest_point(pose);
  from_s = std::max(from_s, t.t_start());
  to_s = std::min(to_s, t.t_end());
  double d = std::numeric_limits<double>::infinity();
  for (double s = from_s; s <= to_s + 1e-9; s += kPathStepS)
    d = std::min(d, (t.sample(s).p_m.head<2>() - rest).norm());
  return ramp_down(d, kOnPathFullM, kOnPathZeroM);
}

double ControlLaw::yaw_gate(const core::plan::BsplineTrajectory& t, double entry_tau, double tau,
                            const core::plan::TrajectorySample& ref, const PoseSample& pose) const {
  const double g = on_reference(ref, pose);
  return g >= 1.0 ? g : std::max(g, on_path(t, std::max(entry_tau, tau - 2.0), tau, pose));
}

double ControlLaw::braking_gap(const core::plan::TrajectorySample& ref,
                               const PoseSample& pose) const {
  const Eigen::Vector2d vr = ref.v_mps.head<2>();
  const double two_a = 2.0 * std::max(robot_.max_accel_mps2, 1e-3);
  return (rest_point(pose) - ref.p_m.head<2>() - vr * vr.norm() / two_a).norm();
}

Eigen::Vector2d ControlLaw::rest_point(const PoseSample& pose) const {
  const Eigen::Vector2d v = pose.velocity_world();
  const double two_a = 2.0 * std::max(robot_.max_accel_mps2, 1e-3);
  return Eigen::Vector2d(pose.x_m, pose.y_m) + v * v.norm() / two_a;
}

bool ControlLaw::turns_away(const core::plan::BsplineTrajectory& t,
                            const Eigen::Vector2d& v) const {
  if (t.empty() || v.norm() < 1e-6) return false;
  // Judged along the path, not its clock: a re-timed trajectory leaves its start at the
  // acceleration limit, and one turning in place barely moved in its first second (maze seed 1,
  // 1030 s: entered at 0.97 m/s, the body overshot into a wall). The look distance is what the
  // robot covers while it falls in behind a reference that starts at rest.
  const double look = v.squaredNorm() / std::max(robot_.max_accel_mps2, 1e-3) + 0.3;
  const Eigen::Vector2d u = v.normalized();
  const core::plan::TrajectorySample a = t.sample(t.t_start());
  // One that leaves its start moving along v (plan.start_at_speed: planned from the robot's
  // velocity) slows for its own bends within the limits: nothing to brake for.
  const Eigen::Vector2d v0 = a.v_mps.head<2>();
  if (v0.norm() > 0.05) return v0.normalized().dot(u) < 0.5;
  Eigen::Vector2d prev = a.p_m.head<2>();
  double walked = 0;
  for (double s = t.t_start() + 0.05;; s += 0.05) {
    const double sc = std::min(s, t.t_end());
    const core::plan::TrajectorySample b = t.sample(sc);
    if (std::abs(wrap_angle(b.yaw_rad - a.yaw_rad)) > 0.5) return true;
    const Eigen::Vector2d chord = (b.p_m - a.p_m).head<2>(), dir = b.v_mps.head<2>();
    if (chord.norm() > 0.05 && chord.normalized().dot(u) < 0.5) return true;
    if (dir.norm() > 0.05 && dir.normalized().dot(u) < 0.5) return true;
    walked += (b.p_m.head<2>() - prev).norm();
    prev = b.p_m.head<2>();
    if (walked >= look) return false;
    if (sc >= t.t_end()) return true;  // it ends within reach: the robot would overshoot its end
  }
}

double ControlLaw::entry_time(const core::plan::BsplineTrajectory& t, const Eigen::Vector2d& at) {
  double best = std::numeric_limits<double>::infinity(), tau = t.t_start();
  for (double s = t.t_start(); s <= std::min(t.t_end(), t.t_start() + 2.0); s += 0.05) {
    const double d = (t.sample(s).p_m.head<2>() - at).norm();
    if (d < best) best = d, tau = s;
  }
  return tau;
}

double ControlLaw::catch_up_time(const core::plan::BsplineTrajectory& t, double tau, double tau_end,
                                 const Eigen::Vector2d& at) {
  constexpr double kStepS = 0.05, kGainM = 0.1, kRiseM = 0.02;
  const double end = std::min({t.t_end(), tau_end, tau + 2.0});
  const double d0 = (t.sample(tau).p_m.head<2>() - at).norm();
  double best = d0, best_s = tau;
  for (double s = tau + kStepS; s <= end + 1e-9; s += kStepS) {
    const double d = (t.sample(s).p_m.head<2>() - at).norm();
    if (d < best)
      best = d, best_s = s;
    else if (d > best + kRiseM)
      break;  // past the first closest approach
  }
  return d0 - best > kGainM ? best_s : tau;
}

double ControlLaw::progress_rate(double position_err_m, double yaw_err_rad, double yaw_gate_rad) {
  const double g = std::max(yaw_gate_rad, 1e-3);
  return std::clamp((0.6 - position_err_m) / 0.3, 0.0, 1.0) *
         std::clamp((2.0 * g - std::abs(yaw_err_rad)) / g, 0.0, 1.0);
}

double ControlLaw::speed_rate(const Eigen::Vector2d& ref_v, const Eigen::Vector2d& robot_v,
                              double lead_mps) {
  const double s = ref_v.norm();
  if (!(lead_mps > 0) || !(s > 1e-6)) return 1.0;
  const double along = std::max(0.0, robot_v.dot(ref_v) / s);
  const double r = (along + lead_mps) / s;
  return std::isfinite(r) ? std::min(1.0, r) : 1.0;
}

}  // namespace storey::firmware
