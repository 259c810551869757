#include "core/plan/bspline_trajectory.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace storey::core::plan {

namespace {
double wrap(double a) {
  return std::remainder(a, 2.0 * M_PI);
}
}  // namespace

const char* to_string(TrajectoryStatus s) {
  switch (s) {
    case TrajectoryStatus::kOk:
      return "ok";
    case TrajectoryStatus::kPolyline:
      return "ok (fell back to the pinned polyline)";
    case TrajectoryStatus::kBadInput:
      return "bad input (empty path or non-finite values)";
    case TrajectoryStatus::kCollision:
      return "collision: even the polyline hits the map";
  }
  return "?";
}

BsplineTrajectory::BsplineTrajectory(std::vector<Eigen::Vector3d> ctrl,
                                     std::vector<double> yaw_ctrl, double dt_s, double t0_s)
    : ctrl_(std::move(ctrl)), yaw_(std::move(yaw_ctrl)), dt_(dt_s), t0_(t0_s) {
  if (yaw_.size() != ctrl_.size()) yaw_.resize(ctrl_.size(), yaw_.empty() ? 0.0 : yaw_.back());
  if (!(dt_ > 0)) dt_ = 1.0;
}

namespace {
// Re-timing's path parameter: planar metres, and kYawLength metres per radian of yaw (the
// ratio of the default speed and yaw-rate limits), so a turn in place has length too.
constexpr double kYawLength = 1.0;
}  // namespace

BsplineTrajectory::Geometry BsplineTrajectory::geometry(double u) const {
  Geometry g{};
  const int n = int(ctrl_.size());
  if (!std::isfinite(u)) u = 0;
  u = std::clamp(u, 0.0, double(n - 3));
  const int i = std::min(int(u), n - 4);
  const double v = u - i, v2 = v * v, v3 = v2 * v, w = 1 - v;
  const double b[4] = {w * w * w / 6, (3 * v3 - 6 * v2 + 4) / 6, (-3 * v3 + 3 * v2 + 3 * v + 1) / 6,
                       v3 / 6};
  const double d[4] = {-w * w / 2, (3 * v2 - 4 * v) / 2, (-3 * v2 + 2 * v + 1) / 2, v2 / 2};
  const double a[4] = {w, 3 * v - 2, -3 * v + 1, v};
  g.p = g.p_u = g.p_uu = Eigen::Vector3d::Zero();
  g.yaw = g.yaw_u = g.yaw_uu = 0;
  for (int k = 0; k < 4; ++k) {
    g.p += b[k] * ctrl_[i + k];
    g.p_u += d[k] * ctrl_[i + k];
    g.p_uu += a[k] * ctrl_[i + k];
    g.yaw += b[k] * yaw_[i + k];
    g.yaw_u += d[k] * yaw_[i + k];
    g.yaw_uu += a[k] * yaw_[i + k];
  }
  g.segment = i;
  return g;
}

bool BsplineTrajectory::path_derivs(const Geometry& g, PathDerivs& d) const {
  const double L2 = kYawLength * kYawLength;
  const double su = std::sqrt(g.p_u.head<2>().squaredNorm() + L2 * g.yaw_u * g.yaw_u);
  d.sigma_u = su;
  if (!(su > 1e-9)) {
    d.p_s = d.p_ss = Eigen::Vector3d::Zero();
    d.yaw_s = d.yaw_ss = 0;
    return false;
  }
  // f_s = f_u / s_u, f_ss = (f_uu - f_s s_uu) / s_u^2, s_uu = (w_u . w_uu) / s_u.
  const double suu = (g.p_u.head<2>().dot(g.p_uu.head<2>()) + L2 * g.yaw_u * g.yaw_uu) / su;
  d.p_s = g.p_u / su;
  d.yaw_s = g.yaw_u / su;
  d.p_ss = (g.p_uu - d.p_s * suu) / (su * su);
  d.yaw_ss = (g.yaw_uu - d.yaw_s * suu) / (su * su);
  return true;
}

TrajectorySample BsplineTrajectory::sample(double t) const {
  TrajectorySample s;
  if (empty()) return s;
  Geometry g;
  if (!retimed()) {
    g = geometry((t - t0_) / dt_);
    s.v_mps = g.p_u / dt_;
    s.a_mps2 = g.p_uu / (dt_ * dt_);
    s.yaw_rate_rps = g.yaw_u / dt_;
  } else {
    // The sample interval holding t; sigma'' is constant in it (sigma_dot^2 linear in sigma).
    const double tau = std::clamp(std::isfinite(t) ? t - t0_ : 0.0, 0.0, w_t_.back());
    size_t k = size_t(std::upper_bound(w_t_.begin(), w_t_.end(), tau) - w_t_.begin());
    k = std::min(k == 0 ? 0 : k - 1, w_t_.size() - 2);
    const double ds = w_s_[k + 1] - w_s_[k];
    const double sdd =
        ds > 0 ? (w_sd_[k + 1] * w_sd_[k + 1] - w_sd_[k] * w_sd_[k]) / (2 * ds) : 0.0;
    const double h = std::min(tau - w_t_[k], w_t_[k + 1] - w_t_[k]);
    const double sd = std::max(0.0, w_sd_[k] + sdd * h);
    const double sg = std::clamp(w_s_[k] + w_sd_[k] * h + 0.5 * sdd * h * h, w_s_[k], w_s_[k + 1]);
    const double f = ds > 0 ? (sg - w_s_[k]) / ds : 0.0;
    g = geometry(w_u_[k] + f * (w_u_[k + 1] - w_u_[k]));
    PathDerivs d;
    if (path_derivs(g, d)) {
      s.v_mps = d.p_s * sd;
      s.a_mps2 = d.p_ss * sd * sd + d.p_s * sdd;
      s.yaw_rate_rps = d.yaw_s * sd;
    }
  }
  s.p_m = g.p;
  s.yaw_rad = g.yaw;
  // Pitch of the terrain along the heading: from the velocity, or the local chord when slow.
  // Slow (turning in place, starting) the ratio of two small numbers is noise: a centimetre of
  // surface noise over a millimetre of travel tilts the box by tens of degrees into the next
  // step. Below half a voxel of chord, level (CollisionChecker::terrain_pitch reads the map).
  // (The same 0.05 bound serves both: m/s of velocity, m of chord.)
  constexpr double kMin = 0.05;
  const int i = g.segment;
  Eigen::Vector3d dir = s.v_mps;
  if (dir.head<2>().norm() < kMin) dir = ctrl_[i + 3] - ctrl_[i];
  const double len = dir.head<2>().norm();
  if (len >= kMin) {
    const double fwd = dir.x() * std::cos(s.yaw_rad) + dir.y() * std::sin(s.yaw_rad);
    s.pitch_rad = std::atan2(fwd >= 0 ? dir.z() : -dir.z(), len);
  }
  return s;
}

BodyPose BsplineTrajectory::pose(double t) const {
  const TrajectorySample s = sample(t);
  return BodyPose{s.p_m, s.yaw_rad, s.pitch_rad, t};
}

double BsplineTrajectory::speed_bound_mps() const {
  double m = 0;
  if (retimed()) {
    PathDerivs d;
    for (size_t k = 0; k < w_u_.size(); ++k)
      if (path_derivs(geometry(w_u_[k]), d)) m = std::max(m, d.p_s.head<2>().norm() * w_sd_[k]);
    return m;
  }
  for (size_t i = 0; i + 1 < ctrl_.size(); ++i)
    m = std::max(m, (ctrl_[i + 1] - ctrl_[i]).head<2>().norm() / dt_);
  return m;
}

double BsplineTrajectory::accel_bound_mps2() const {
  double m = 0;
  if (retimed()) {
    for (double t = t_start(); t <= t_end(); t += 0.01)
      m = std::max(m, sample(t).a_mps2.head<2>().norm());
    return m;
  }
  for (size_t i = 0; i + 2 < ctrl_.size(); ++i)
    m = std::max(m, (ctrl_[i + 2] - 2 * ctrl_[i + 1] + ctrl_[i]).head<2>().norm() / (dt_ * dt_));
  return m;
}

// Time-optimal timing along a fixed path (the classic phase-plane method, discretised): with
// x = sigma_dot^2, the path acceleration x' / 2 = sigma_ddot enters every limit linearly,
//   planar:  | p_ss x + p_s x' / 2 |_xy <= a_max,   yaw:  | yaw_ss x + yaw_s x' / 2 | <= wa_max,
// the speed limits bound x alone (|p_s|_xy^2 x <= v_max^2, yaw_s^2 x <= w_max^2), and so does the
// existence of an admissible x' (the maximum velocity curve: at a corner the normal acceleration
// p_ss x alone reaches a_max). A backward pass from rest at the end then a forward pass from rest
// at the start, each step taking the largest admissible |x'|, give the fastest x along sigma;
// time follows from t' = 1 / sigma_dot.
void BsplineTrajectory::retime(const RobotModel& robot, int samples_per_knot, double margin,
                               double yaw_margin, double start_speed_mps) {
  w_t_.clear();
  w_u_.clear();
  w_s_.clear();
  w_sd_.clear();
  if (empty()) return;
  margin = std::clamp(margin, 0.1, 1.0);
  yaw_margin = std::clamp(yaw_margin, 0.1, 1.0);
  const double vmax = margin * std::max(robot.max_speed_mps, 1e-3);
  const double wmax = yaw_margin * std::max(robot.max_yaw_rate_rps, 1e-3);
  const double amax = margin * std::max(robot.max_accel_mps2, 1e-3);
  const double wamax = yaw_margin * std::max(robot.max_yaw_accel_rps2, 1e-3);
  const int knots = int(ctrl_.size()) - 3;
  const int K = knots * std::max(1, samples_per_knot);  // intervals
  std::vector<PathDerivs> d(size_t(K) + 1);
  std::vector<uint8_t> moving(size_t(K) + 1);
  w_u_.resize(size_t(K) + 1);
  w_s_.assign(size_t(K) + 1, 0.0);
  for (int k = 0; k <= K; ++k) {
    w_u_[k] = double(knots) * k / K;
    moving[k] = path_derivs(geometry(w_u_[k]), d[k]);
  }
  // sigma by Simpson's rule on d sigma / du.
  for (int k = 0; k < K; ++k) {
    PathDerivs mid;
    path_derivs(geometry(0.5 * (w_u_[k] + w_u_[k + 1])), mid);
    w_s_[k + 1] =
        w_s_[k] + (w_u_[k + 1] - w_u_[k]) / 6 * (d[k].sigma_u + 4 * mid.sigma_u + d[k + 1].sigma_u);
  }
  // Admissible x' at sample k for x: [lo, hi]; empty (lo > hi) if none.
  constexpr double kInf = std::numeric_limits<double>::infinity();
  auto admissible = [&](int k, double x) -> std::pair<double, double> {
    double lo = -kInf, hi = kInf;
    const Eigen::Vector2d P = d[k].p_ss.head<2>() * x, Q = 0.5 * d[k].p_s.head<2>();
    const double q2 = Q.squaredNorm();
    if (q2 < 1e-18) {
      if (P.norm() > amax) return {1, -1};
    } else {
      const double pq = P.dot(Q), disc = pq * pq - q2 * (P.squaredNorm() - amax * amax);
      if (disc < 0) return {1, -1};
      lo = std::max(lo, (-pq - std::sqrt(disc)) / q2);
      hi = std::min(hi, (-pq + std::sqrt(disc)) / q2);
    }
    const double yp = d[k].yaw_ss * x, yq = 0.5 * d[k].yaw_s;
    if (std::abs(yq) < 1e-9) {
      if (std::abs(yp) > wamax) return {1, -1};
    } else {
      const double e1 = (-wamax - yp) / yq, e2 = (wamax - yp) / yq;
      lo = std::max(lo, std::min(e1, e2));
      hi = std::min(hi, std::max(e1, e2));
    }
    return {lo, hi};
  };
  // The maximum velocity curve: the speed limits, then the largest x with an admissible x'
  // (the admissible (x, x') set is convex and holds (0, 0), so its x form an interval).
  // Where the curve stands still, or its direction turns between two samples by more than the
  // sampled curvature says (the turn sits between them), the bound comes from that turn.
  std::vector<double> mvc(size_t(K) + 1, 0.0);
  const double a_turn = std::min(amax, kYawLength * wamax);
  for (int k = 0; k <= K; ++k) {
    if (!moving[k]) continue;  // at rest
    double cap = 1e6;
    const double vxy = d[k].p_s.head<2>().squaredNorm(), vy = d[k].yaw_s * d[k].yaw_s;
    if (vxy > 0) cap = std::min(cap, vmax * vmax / vxy);
    if (vy > 0) cap = std::min(cap, wmax * wmax / vy);
    auto dir = [&](int j) {
      return Eigen::Vector3d(d[j].p_s.x(), d[j].p_s.y(), kYawLength * d[j].yaw_s);
    };
    for (int j : {k - 1, k + 1}) {
      if (j < 0 || j > K || !moving[j]) continue;
      const double ds = std::abs(w_s_[j] - w_s_[k]);
      const double turn = std::acos(std::clamp(dir(j).dot(dir(k)), -1.0, 1.0));
      if (turn > 1e-6) cap = std::min(cap, a_turn * ds / turn);
    }
    auto ok = [&](double x) {
      const auto [lo, hi] = admissible(k, x);
      return lo <= hi;
    };
    if (ok(cap)) {
      mvc[k] = cap;
      continue;
    }
    double a = 0, b = cap;
    for (int it = 0; it < 40; ++it) (ok(0.5 * (a + b)) ? a : b) = 0.5 * (a + b);
    mvc[k] = a;
  }
  // Backward pass (deceleration into the end's rest), then forward (acceleration from the
  // start's, or from start_speed_mps where the backward pass allows it). A step's x' is the
  // tighter of its two ends' bounds.
  std::vector<double> x(size_t(K) + 1, 0.0);
  x[K] = 0;
  for (int k = K - 1; k >= 0; --k) {
    const double ds = w_s_[k + 1] - w_s_[k];
    double dec = -admissible(k + 1, x[k + 1]).first;  // largest deceleration, > 0
    if (!(dec > 0)) dec = 0;
    double cand = std::min(mvc[k], x[k + 1] + dec * ds);
    const double dec0 = -admissible(k, cand).first;
    if (dec0 >= 0 && dec0 < dec) cand = std::min(cand, x[k + 1] + dec0 * ds);
    x[k] = std::max(0.0, cand);
  }
  double prev = 0;
  for (int k = 0; k <= K; ++k) {
    if (k == 0) {
      const double v0 = std::isfinite(start_speed_mps) ? std::max(0.0, start_speed_mps) : 0.0;
      x[0] = moving[0] ? std::min(x[0], v0 * v0) : 0.0;
    } else {
      const double ds = w_s_[k] - w_s_[k - 1];
      double acc = admissible(k - 1, prev).second;
      if (!(acc > 0)) acc = 0;
      double cand = std::min(x[k], prev + acc * ds);
      const double acc1 = admissible(k, cand).second;
      if (acc1 >= 0 && acc1 < acc) cand = std::min(cand, prev + acc1 * ds);
      x[k] = std::max(0.0, cand);
    }
    prev = x[k];
  }
  w_sd_.resize(size_t(K) + 1);
  for (int k = 0; k <= K; ++k) w_sd_[k] = std::sqrt(x[k]);
  w_t_.assign(size_t(K) + 1, 0.0);
  for (int k = 0; k < K; ++k) {
    const double ds = w_s_[k + 1] - w_s_[k], v = w_sd_[k] + w_sd_[k + 1];
    // Both ends at rest with length between them (two stopping points one sample apart): start
    // and stop within the interval.
    const double dt = ds <= 0 ? 0.0 : v > 1e-9 ? 2 * ds / v : 2 * std::sqrt(ds / a_turn);
    w_t_[k + 1] = w_t_[k] + dt;
  }
}

bool TrajectoryBuilder::segment_ok(const map::MapView& view, CollisionChecker& checker,
                                   const Eigen::Vector3d& a, const Eigen::Vector3d& b) const {
  const double s = view.voxel_size_m();
  const double step = robot_.step_height_m;
  const int n = std::max(1, int(std::ceil((b - a).head<2>().norm() / (0.5 * s))));
  for (int k = 0; k <= n; ++k) {
    const Eigen::Vector3d p = a + (b - a) * (double(k) / n);
    const auto sp = view.support_surface_near(p.cast<float>(), step);
    if (!sp || sp->state != map::TravState::kTraversable) return false;
    if (opt_.reachable_only && !sp->reachable) return false;
  }
  return !checker.check_segment(view, a, b, std::nan("")).collides;
}

BsplineTrajectory TrajectoryBuilder::fit(std::span<const Eigen::Vector3d> wp,
                                         std::span<const uint8_t> pinned, double yaw_start,
                                         std::optional<double> yaw_goal, double t0,
                                         const Eigen::Vector2d& v0) const {
  std::vector<Eigen::Vector3d> c;
  const double spacing = std::max(opt_.control_spacing_m, 1e-2);
  // Leaving at speed: P_0, P_1, P_2 = s - h u, s, s + h u put the curve's start on s with its
  // tangent along u = v0 / |v0|. h is at most half the first control step, so the next control
  // point lies beyond P_2 when the path carries on along u.
  const double speed = v0.norm();
  const bool at_speed = opt_.retime && wp.size() >= 2 && speed > 1e-3;
  if (at_speed) {
    const Eigen::Vector3d u(v0.x() / speed, v0.y() / speed, 0.0);
    const double h = 0.5 * std::min(spacing, (wp[1] - wp[0]).head<2>().norm());
    c = {wp[0] - h * u, wp[0], wp[0] + h * u};
  } else {
    c.insert(c.end(), 3, wp[0]);
  }
  for (size_t k = 0; k + 1 < wp.size(); ++k) {
    const Eigen::Vector3d d = wp[k + 1] - wp[k];
    const int nseg = std::max(1, int(std::ceil(d.norm() / spacing)));
    for (int j = 1; j < nseg; ++j) c.push_back(wp[k] + d * (double(j) / nseg));
    c.push_back(wp[k + 1]);
    if (pinned[k + 1] || k + 2 == wp.size()) c.insert(c.end(), 2, wp[k + 1]);
  }
  if (wp.size() == 1) c.insert(c.end(), 3, wp[0]);  // single point: start and end triples

  // Yaw control points: start yaw on the start triple, then the travel direction through each
  // point (next distinct minus previous distinct), the goal yaw on the end triple; unwrapped.
  const int n = int(c.size());
  std::vector<double> y(size_t(n), yaw_start);
  double carry = yaw_start;
  bool backwards = true;  // still on the flight the path starts down, facing up it
  for (int q = 3; q < n - 3; ++q) {
    int lo = q, hi = q;
    while (lo > 0 && (c[lo] - c[q]).head<2>().norm() < 1e-6) --lo;
    while (hi < n - 1 && (c[hi] - c[q]).head<2>().norm() < 1e-6) ++hi;
    const Eigen::Vector3d d = c[hi] - c[lo];
    if (d.head<2>().norm() > 1e-6) {
      carry = std::atan2(d.y(), d.x());
      // A path that starts down a flight the robot stands on facing up it is walked backwards
      // until the flight ends: the 0.7 m body has no room to turn round between a flight's side
      // walls (a robot that had climbed part of test_stair could plan no way back), and the
      // LiDAR sees all round. Paths that reach a flight from level ground descend it forwards.
      backwards = backwards && d.z() < 0 && is_flight(robot_, -d.z(), d.head<2>().norm()) &&
                  std::abs(wrap(carry + M_PI - yaw_start)) < 0.5 * M_PI;
      if (backwards) carry += M_PI;
    }
    y[q] = carry;
  }
  for (int q = std::max(3, n - 3); q < n; ++q) y[q] = yaw_goal ? *yaw_goal : carry;
  for (int q = 1; q < n; ++q) y[q] = y[q - 1] + wrap(y[q] - y[q - 1]);

  // Halfway points next to every point at rest (a triple): the step from rest to the next
  // control point is a second difference of a whole spacing, and with one knot interval for the
  // whole curve the acceleration bound it sets, sqrt(spacing / a_max), held every metre of the
  // curve to 0.71 v_max (0.5 m spacing, 1 m/s, 1 m/s^2). Halved, it allows v_max.
  const double vmax = std::max(robot_.max_speed_mps, 1e-3);
  const double wmax = std::max(robot_.max_yaw_rate_rps, 1e-3);
  const double amax = std::max(robot_.max_accel_mps2, 1e-3);
  const double wamax = std::max(robot_.max_yaw_accel_rps2, 1e-3);
  // Control points a and b of c coincide (a point at rest); false out of range.
  auto at_rest = [&](int a, int b) {
    return a >= 0 && b < int(c.size()) && (c[size_t(a)] - c[size_t(b)]).norm() < 1e-9;
  };
  // The knot interval the travel needs (speed and acceleration bounds of the positions).
  auto travel_dt = [&]() {
    double dt = 1e-3;
    for (size_t q = 0; q + 1 < c.size(); ++q)
      dt = std::max(dt, (c[q + 1] - c[q]).head<2>().norm() / vmax);
    for (size_t q = 0; q + 2 < c.size(); ++q)
      dt = std::max(dt, std::sqrt((c[q + 2] - 2 * c[q + 1] + c[q]).head<2>().norm() / amax));
    return dt;
  };
  {
    std::vector<Eigen::Vector3d> c1;
    std::vector<double> y1;
    for (int q = 0; q < n; ++q) {
      if (q > 0 && !at_rest(q - 1, q) && (at_rest(q - 2, q - 1) || at_rest(q, q + 1))) {
        c1.push_back(0.5 * (c[size_t(q - 1)] + c[size_t(q)]));
        y1.push_back(at_rest(q - 2, q - 1) ? y[size_t(q)] : y[size_t(q - 1)]);  // the travel's yaw
      }
      c1.push_back(c[size_t(q)]);
      y1.push_back(y[size_t(q)]);
    }
    c.swap(c1);
    y.swap(y1);
  }
  // Graded corners (TrajectoryOptions::grade_corners): a corner of the polyline is a second
  // difference of 2 h sin(theta / 2) at spacing h, and with one knot interval for the whole curve
  // one corner slows every metre of it (a right angle between two 4 m legs: 0.84 v_max, with
  // the yaw spread below already splitting the corner's intervals). Halving the spacing on both
  // sides of a corner (up to three times) halves it, and the steps into the halved spacing,
  // h / 2, stay within what the straight walk at v_max needs: the curve slows for the corner
  // only, and hugs it closer.
  if (opt_.grade_corners) {
    const double bound = amax * std::pow(spacing / vmax, 2) * (1 + 1e-9);
    for (int pass = 0; pass < 3; ++pass) {
      const int m = int(c.size());
      std::vector<uint8_t> split(size_t(m), 0);  // split the interval (q, q + 1)
      bool any = false;
      for (int q = 1; q + 1 < m; ++q) {
        if (at_rest(q - 1, q) || at_rest(q, q + 1)) continue;
        if ((c[q + 1] - 2 * c[q] + c[q - 1]).head<2>().norm() <= bound) continue;
        split[q - 1] = split[q] = 1;
        any = true;
      }
      if (!any) break;
      std::vector<Eigen::Vector3d> c1;
      std::vector<double> y1;
      for (int q = 0; q < m; ++q) {
        c1.push_back(c[q]);
        y1.push_back(y[q]);
        if (split[q] && q + 1 < m) {
          c1.push_back(0.5 * (c[q] + c[q + 1]));
          y1.push_back(0.5 * (y[q] + y[q + 1]));
        }
      }
      c.swap(c1);
      y.swap(y1);
    }
  }
  // Spread large yaw changes over several intervals (turning while moving slowly, or in place at
  // a triple): with one knot interval for the whole curve, a single half turn between two
  // control points would otherwise slow down every metre of it. Budget per interval: what the
  // yaw-rate and yaw-acceleration limits allow in the interval the travel needs (at least
  // w_max / wa_max, where turning in place reaches w_max), less a tenth. It was half the rate
  // limit's share of the nominal spacing / v_max, and with the travel's 0.71 s interval the robot
  // turned at 0.35 rad/s: 60 % of the house's exploration time went to turning on the spot.
  const double dt_ref = std::max(travel_dt(), wmax / wamax);
  const double yaw_step = 0.9 * std::min(wmax * dt_ref, wamax * dt_ref * dt_ref);
  const int n1 = int(c.size());
  std::vector<Eigen::Vector3d> c2;
  std::vector<double> y2;
  c2.reserve(c.size());
  y2.reserve(c.size());
  // A turn next to a point at rest is made there, in place (before leaving it, after arriving).
  for (int q = 0; q < n1; ++q) {
    if (q > 0) {
      const int k = int(std::ceil(std::abs(y[q] - y[q - 1]) / yaw_step - 1e-9));
      const bool moves = !at_rest(q - 1, q);
      const bool leaving = moves && at_rest(q - 2, q - 1), arriving = moves && at_rest(q, q + 1);
      if (k > 1 && arriving && !leaving) {
        c2.push_back(c[q]);
        y2.push_back(y[q - 1]);
      }
      for (int j = 1; j < k; ++j) {
        const double f = double(j) / k;
        c2.push_back(leaving ? c[q - 1] : arriving ? c[q] : c[q - 1] + f * (c[q] - c[q - 1]));
        y2.push_back(y[q - 1] + f * (y[q] - y[q - 1]));
      }
    }
    c2.push_back(c[q]);
    y2.push_back(y[q]);
  }
  c.swap(c2);
  y.swap(y2);
  const int nc = int(c.size());

  // One knot interval satisfying every limit through the convex-hull bounds.
  double dt = travel_dt();
  for (int q = 0; q + 1 < nc; ++q) dt = std::max(dt, std::abs(y[q + 1] - y[q]) / wmax);
  for (int q = 0; q + 2 < nc; ++q)
    dt = std::max(dt, std::sqrt(std::abs(y[q + 2] - 2 * y[q + 1] + y[q]) / wamax));
  BsplineTrajectory t(std::move(c), std::move(y), dt * (1 + 1e-9), t0);
  if (opt_.retime) t.retime(robot_, 16, 0.97, opt_.retime_yaw_share, at_speed ? speed : 0.0);
  return t;
}

TrajectoryResult TrajectoryBuilder::build(const map::MapView& view, CollisionChecker& checker,
                                          std::span<const Eigen::Vector3d> path, double yaw_start,
                                          std::optional<double> yaw_goal, double t0,
                                          std::optional<Eigen::Vector2d> start_velocity) {
  TrajectoryResult r;
  if (path.empty() || !std::isfinite(yaw_start) || !std::isfinite(t0) ||
      (yaw_goal && !std::isfinite(*yaw_goal)) || (start_velocity && !start_velocity->allFinite()))
    return r;
  const Eigen::Vector2d v0 = start_velocity.value_or(Eigen::Vector2d::Zero());
  for (const auto& p : path)
    if (!p.allFinite()) return r;

  // 1. Shortcut: from each kept point, gallop (1, 2, 4, ...) then bisect to the farthest point
  // whose segment passes, so a long straight stretch costs O(log n) segment checks.
  std::vector<Eigen::Vector3d>& wp = r.waypoints_m;
  wp.push_back(path[0]);
  const size_t n = path.size();
  size_t i = 0;
  while (i + 1 < n) {
    size_t good = i + 1;
    if (opt_.shortcut) {
      size_t stepk = 1, bad = n;
      while (good + stepk < n) {
        ++r.segment_checks;
        if (!segment_ok(view, checker, path[i], path[good + stepk])) {
          bad = good + stepk;
          break;
        }
        good += stepk;
        stepk *= 2;
      }
      if (bad == n && good + 1 < n) {
        ++r.segment_checks;
        if (segment_ok(view, checker, path[i], path[n - 1]))
          good = n - 1;
        else
          bad = n - 1;
      }
      while (bad - good > 1) {
        const size_t mid = good + (bad - good) / 2;
        ++r.segment_checks;
        if (segment_ok(view, checker, path[i], path[mid]))
          good = mid;
        else
          bad = mid;
      }
    }
    wp.push_back(path[good]);
    i = good;
  }

  // 2-4. Fit, check, pin the vertex nearest to a hit, repeat. If the pruned polyline keeps
  // colliding (shortcut corners hug door frames, where the long body cannot turn), do the same
  // on the A* path itself, decimated to the control spacing (it keeps the soft clearance);
  // finally the pinned polyline.
  auto start_speed = [](const BsplineTrajectory& t) {
    return t.sample(t.t_start()).v_mps.head<2>().norm();
  };
  auto check = [&](const BsplineTrajectory& t) {
    return checker.check_ahead(
        view, [&](double s) { return t.pose(s); }, t.t_start(), t.duration(), 0.0);
  };
  auto repair_loop = [&](const std::vector<Eigen::Vector3d>& w) {
    std::vector<uint8_t> pinned(w.size(), 0);
    for (int attempt = 0;; ++attempt) {
      r.trajectory = fit(w, pinned, yaw_start, yaw_goal, t0, v0);
      r.start_speed_mps = start_speed(r.trajectory);
      r.hit = check(r.trajectory);
      if (!r.hit.collides) return true;
      if (attempt >= opt_.max_repairs) return false;
      const Eigen::Vector3d hp = r.trajectory.sample(r.hit.t_s).p_m;
      size_t best = 0;
      double best_d = std::numeric_limits<double>::infinity();
      for (size_t k = 1; k + 1 < w.size(); ++k) {
        const double dd = (w[k] - hp).norm();
        if (!pinned[k] && dd < best_d) {
          best_d = dd;
          best = k;
        }
      }
      if (best == 0) return false;  // nothing left to pin
      pinned[best] = 1;
      ++r.repairs;
    }
  };
  if (repair_loop(wp)) {
    r.status = TrajectoryStatus::kOk;
    return r;
  }
  if (opt_.shortcut && n > 2) {
    std::vector<Eigen::Vector3d> dense;
    double since = 0;
    dense.push_back(path[0]);
    for (size_t k = 1; k + 1 < n; ++k) {
      since += (path[k] - path[k - 1]).norm();
      if (since >= opt_.control_spacing_m) {
        dense.push_back(path[k]);
        since = 0;
      }
    }
    dense.push_back(path[n - 1]);
    if (repair_loop(dense)) {
      r.waypoints_m = std::move(dense);
      r.status = TrajectoryStatus::kOk;
      return r;
    }
  }
  std::vector<uint8_t> all(wp.size(), 1);
  r.trajectory = fit(wp, all, yaw_start, yaw_goal, t0, v0);
  r.start_speed_mps = start_speed(r.trajectory);
  r.hit = check(r.trajectory);
  r.status = r.hit.collides ? TrajectoryStatus::kCollision : TrajectoryStatus::kPolyline;
  return r;
}

}  // namespace storey::core::plan
