#include "core/plan/escape.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <span>

namespace storey::core::plan {

bool can_turn_at(CollisionChecker& checker, const map::MapView& view, const Eigen::Vector3d& foot,
                 double yaw) {
  constexpr int kYaws = 24;  // 15 deg
  BodyPose p[kYaws];
  for (int k = 0; k < kYaws; ++k) p[k] = BodyPose{foot, yaw + 2.0 * M_PI * k / kYaws, 0.0, 0.0};
  return !checker.check_poses(view, std::span<const BodyPose>(p, kYaws)).collides;
}

std::optional<StraightWalk> straight_walk(CollisionChecker& checker, const map::MapView& view,
                                          const RobotModel& robot,
                                          const std::vector<Eigen::Vector3d>& pts, double yaw,
                                          double t0, double from_yaw) {
  if (pts.size() < 2) return std::nullopt;
  double len = 0;
  for (size_t j = 1; j < pts.size(); ++j) len += (pts[j] - pts[j - 1]).head<2>().norm();
  const double seg = len / double(pts.size() - 1);
  // Knot interval: half speed, and the acceleration limit at the tripled ends.
  const double dt = std::max({seg / (0.5 * robot.max_speed_mps),
                              std::sqrt(seg / std::max(robot.max_accel_mps2, 1e-3)), 1e-3});
  const double turn = std::isfinite(from_yaw) ? std::remainder(yaw - from_yaw, 2.0 * M_PI) : 0.0;
  // Yaw per knot on the spot: half the yaw-rate limit, and half the yaw-acceleration limit over
  // one knot interval (the B-spline's yaw rate ramps up across it).
  const double per_knot = std::max(
      0.5 * std::min(robot.max_yaw_rate_rps * dt, robot.max_yaw_accel_rps2 * dt * dt), 1e-3);
  // The shorter way round only: the body box is centred on its foot and symmetric, so the longer
  // way sweeps every orientation the shorter one does.
  // Below kTurnRad the tracking law turns the body while it walks, as without from_yaw: a level
  // box turning on the spot on a flight (pitch 0 at a standing pose) meets the treads. From
  // 0.1 rad, house seed 8 never reached its upper floor.
  constexpr double kTurnRad = 0.5;
  const int m = std::abs(turn) > kTurnRad ? int(std::ceil(std::abs(turn) / per_knot)) : 0;
  std::vector<Eigen::Vector3d> c(3 + size_t(m), pts.front());  // tripled: starts exactly there
  std::vector<double> yaws(3, m > 0 ? from_yaw : yaw);
  for (int j = 1; j <= m; ++j) yaws.push_back(from_yaw + turn * double(j) / m);
  c.insert(c.end(), pts.begin() + 1, pts.end());
  c.insert(c.end(), 2, pts.back());
  yaws.resize(c.size(), m > 0 ? from_yaw + turn : yaw);
  BsplineTrajectory t(std::move(c), std::move(yaws), dt, t0);
  const CollisionHit hit = checker.check_ahead(
      view, [&](double tt) { return t.pose(tt); }, t.t_start(), t.duration(), 0.0);
  if (hit.collides) return std::nullopt;
  return StraightWalk{std::move(t), pts.front(), pts.back()};
}

std::optional<Eigen::Vector3d> straight_rest_point(CollisionChecker& checker,
                                                   const map::MapView& view,
                                                   const RobotModel& robot,
                                                   const Eigen::Vector3d& foot, double yaw,
                                                   const Eigen::Vector2d& v, double t_s) {
  const double d = v.squaredNorm() / (2.0 * std::max(robot.max_accel_mps2, 1e-3));
  if (!std::isfinite(d) || d < 0.05) return std::nullopt;
  const Eigen::Vector2d u = v.normalized();
  std::vector<BodyPose> way;
  double z = foot.z();
  Eigen::Vector3d rest = foot;
  for (double s = 0.05; s <= d + 1e-9; s += 0.05) {
    const Eigen::Vector2d q = foot.head<2>() + std::min(s, d) * u;
    const auto sp = view.support_surface_near(Eigen::Vector3f(float(q.x()), float(q.y()), float(z)),
                                              robot.step_height_m);
    if (sp && sp->state == map::TravState::kUntraversable) return std::nullopt;
    if (sp) z = sp->height_m;
    rest = Eigen::Vector3d(q.x(), q.y(), z);
    for (double dyaw : {0.0, -0.6, 0.6}) way.push_back(BodyPose{rest, yaw + dyaw, 0.0, t_s});
  }
  if (way.empty() || checker.check_poses(view, way).collides) return std::nullopt;
  return rest;
}

std::optional<StraightWalk> escape_to_turn(CollisionChecker& checker, const map::MapView& view,
                                           const RobotModel& robot, const Eigen::Vector3d& start,
                                           double yaw, double t0, double radius_m,
                                           const Eigen::Vector3f* away_from) {
  auto dist_xy = [&](const Eigen::Vector3d& p) {
    return (p.head<2>() - away_from->head<2>().cast<double>()).norm();
  };
  constexpr int kDirs = 16;
  const double spacing = 0.1;
  for (double d = 0.1; d <= radius_m + 1e-9; d += 0.1)
    for (int a = 0; a < kDirs; ++a) {
      const double th = 2.0 * M_PI * a / kDirs;
      Eigen::Vector3d b = start + Eigen::Vector3d(d * std::cos(th), d * std::sin(th), 0);
      const auto s = view.support_surface_near(b.cast<float>(), robot.step_height_m);
      if (!s || !s->reachable) continue;
      if (away_from && dist_xy(b) < dist_xy(start) + 0.5 * d) continue;
      b.z() = s->height_m;
      if (!can_turn_at(checker, view, b, yaw)) continue;
      std::vector<Eigen::Vector3d> pts;
      const int n = std::max(1, int(std::ceil(d / spacing)));
      for (int j = 0; j <= n; ++j) pts.push_back(start + (b - start) * (double(j) / n));
      if (auto w = straight_walk(checker, view, robot, pts, yaw, t0)) return w;
    }
  return std::nullopt;
}

RestOnTrajectory rest_on_trajectory(CollisionChecker& checker, const map::MapView& view,
                                    const RobotModel& robot, const BsplineTrajectory& traj,
                                    const Eigen::Vector3d& foot, const Eigen::Vector2d& v,
                                    double t_on, double t_s, bool along_motion) {
  using Kind = RestOnTrajectory::Kind;
  RestOnTrajectory out;
  const double d = v.squaredNorm() / (2.0 * std::max(robot.max_accel_mps2, 1e-3));
  if (!std::isfinite(d) || d < 0.05 || traj.empty()) return out;
  double s0 = NAN, best = 0.3;
  for (double s = std::max(traj.t_start(), t_on - 2.0); s <= std::min(traj.t_end(), t_on + 2.0);
       s += 0.02) {
    const double e = (traj.sample(s).p_m - foot).head<2>().norm();
    if (e < best) best = e, s0 = s;
  }
  if (!std::isfinite(s0)) return out;
  std::vector<BodyPose> way;
  double arc = 0, next = 0.05;
  Eigen::Vector3d prev = traj.sample(s0).p_m;
  for (double s = s0 + 0.02; s <= traj.t_end() + 1e-9 && arc < d; s += 0.02) {
    const Eigen::Vector3d p = traj.sample(s).p_m;
    arc += (p - prev).head<2>().norm();
    prev = p;
    if (arc >= next || arc >= d || s + 0.02 > traj.t_end()) {
      BodyPose q = traj.pose(s);
      q.t_s = t_s;
      way.push_back(q);
      next += 0.05;
    }
  }
  // Only a trajectory the robot moves along: the one last published may be one the control
  // task has not entered yet (it brakes on the one before), starting where that braking ends
  // and heading back; a rest point predicted along it lay behind the robot (house seed 5,
  // session 32: a new start 0.17 m beside where the body came to rest).
  const Eigen::Vector2d to_rest =
      way.empty() ? Eigen::Vector2d::Zero() : Eigen::Vector2d((way.back().foot_m - foot).head<2>());
  if (along_motion && !(to_rest.dot(v) > 0.5 * to_rest.norm() * v.norm())) return out;
  if (way.empty() || checker.check_poses(view, way).collides) {
    out.kind = Kind::kBlocked;
    return out;
  }
  out.kind = Kind::kRest;
  out.pose = way.back();
  return out;
}

bool NoProgressWatchdog::stalled(const Eigen::Vector3d& foot, double yaw, double t_s,
                                 bool has_target, double period_s) {
  const bool moved = !foot_m_.allFinite() || (foot - foot_m_).norm() > 0.15 ||
                     std::abs(std::remainder(yaw - yaw_, 2.0 * M_PI)) > 0.3;
  if (!has_target || moved || period_s <= 0) {
    foot_m_ = foot;
    yaw_ = yaw;
    t_s_ = t_s;
    return false;
  }
  if (t_s - t_s_ < period_s) return false;
  t_s_ = t_s;
  return true;
}

Eigen::Vector3f blocking_point(const map::MapView& view, const RobotModel& robot,
                               const Eigen::Vector3d& foot, double yaw) {
  const double vs = view.voxel_size_m();
  Eigen::Vector3f best = Eigen::Vector3f::Zero();
  double best_d = std::numeric_limits<double>::infinity();
  for (double dx = -0.6; dx <= 0.6 + 1e-9; dx += vs)
    for (double dy = -0.6; dy <= 0.6 + 1e-9; dy += vs)
      for (double h = robot.step_height_m; h <= robot.body_height_m + 1e-9; h += vs) {
        const double d = std::hypot(dx, dy);
        if (d >= best_d) continue;
        const Eigen::Vector3f q(float(foot.x() + dx), float(foot.y() + dy), float(foot.z() + h));
        if (view.occupancy(q) == map::Occupancy::kOccupied) best = q, best_d = d;
      }
  if (std::isfinite(best_d)) return best;
  return Eigen::Vector3f(float(foot.x() + 0.45 * std::cos(yaw)),
                         float(foot.y() + 0.45 * std::sin(yaw)),
                         float(foot.z() + 0.5 * robot.body_height_m));
}

std::optional<Eigen::Vector3d> nearest_free_foot(CollisionChecker& checker,
                                                 const map::MapView& view, const BodyPose& pose,
                                                 double radius_m) {
  if (!checker.check_poses(view, std::span<const BodyPose>(&pose, 1)).collides) return pose.foot_m;
  for (double d = 0.05; d <= radius_m + 1e-9; d += 0.05)
    for (int k = 0; k < 16; ++k) {
      const double a = k * M_PI / 8;
      BodyPose p = pose;
      p.foot_m = pose.foot_m + d * Eigen::Vector3d(std::cos(a), std::sin(a), 0);
      if (!checker.check_poses(view, std::span<const BodyPose>(&p, 1)).collides) return p.foot_m;
    }
  return std::nullopt;
}

}  // namespace storey::core::plan
