#include "core/plan/path_centring.hpp"

#include <algorithm>
#include <cmath>

namespace storey::core::plan {

namespace {

// An obstacle for the body standing on surface height h: an occupied voxel whose surface height
// lies between h + step and h + body top, in the column at (x, y).
bool obstacle_at(const map::MapView& view, int32_t kx, int32_t ky, double h) {
  const RobotModel& r = view.robot();
  const double s = view.voxel_size_m();
  const double z_lo = h + r.step_height_m, z_hi = h + r.body_height_m + r.body_margin_m;
  for (int32_t kz = int32_t(std::floor(z_lo / s)); kz <= int32_t(std::floor(z_hi / s)); ++kz) {
    const auto zs = view.surface_height_m({kx, ky, kz});
    if (zs && *zs >= z_lo && *zs < z_hi) return true;
  }
  return false;
}

// A step between consecutive path points that climbs a flight (a rise over the step's half
// height, steeper than 0.6 max_slope: stairs' mean grade is ~30 deg, ramps for legged robots
// stay under ~15 deg). A ramp's points are centred and shaped like level ones, with the
// ground following the ramp's grade.
bool flight_step(const RobotModel& r, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                 double voxel_m) {
  return is_flight(r, std::abs(b.z() - a.z()), std::max((b - a).head<2>().norm(), voxel_m));
}

}  // namespace

PathCentringStats centre_path(const map::MapView& view, std::vector<Eigen::Vector3d>& points,
                              const PathCentringOptions& opt) {
  PathCentringStats st;
  const size_t n = points.size();
  if (n < 3) return st;
  const RobotModel& r = view.robot();
  const double s = view.voxel_size_m();
  const double keep =
      opt.keep_clear_m >= 0 ? opt.keep_clear_m : 0.5 * r.body_length_m + r.body_margin_m;
  const double reach = opt.max_shift_m + keep;
  const int rv = int(std::ceil(reach / s));
  const int rs = int(std::floor(opt.max_shift_m / opt.sample_m + 1e-9));
  std::vector<Eigen::Vector2d> obstacles;
  std::vector<std::pair<double, Eigen::Vector2d>> cands;
  const std::vector<Eigen::Vector3d> original = points;
  for (size_t i = 1; i + 1 < n; ++i) {
    const Eigen::Vector3d p = original[i];
    // On a flight (a neighbour a level away) the treads ahead would read as obstacles: the
    // flight's own shaping (shape_flights) centres it.
    if (flight_step(r, original[i - 1], p, s) || flight_step(r, p, original[i + 1], s)) continue;
    // The ground's grade along the path (a ramp; zero on level ground): a column's ground is
    // expected at p.z() + grade . (column - p).
    const Eigen::Vector2d span = (original[i + 1] - original[i - 1]).head<2>();
    const Eigen::Vector2d grade =
        span.norm() > 1e-6 ? Eigen::Vector2d(span * ((original[i + 1].z() - original[i - 1].z()) /
                                                     span.squaredNorm()))
                           : Eigen::Vector2d::Zero();
    const int32_t cx = int32_t(std::floor(p.x() / s)), cy = int32_t(std::floor(p.y() / s));
    // Obstacle columns around the point, at its own level (stairs: each tread has its own band).
    obstacles.clear();
    for (int dx = -rv; dx <= rv; ++dx)
      for (int dy = -rv; dy <= rv; ++dy) {
        const Eigen::Vector2d c((cx + dx + 0.5) * s, (cy + dy + 0.5) * s);
        if ((dx * dx + dy * dy) * s * s <= reach * reach &&
            obstacle_at(view, cx + dx, cy + dy, p.z() + grade.dot(c - p.head<2>())))
          obstacles.push_back(c);
      }
    if (obstacles.empty()) continue;
    // Clearance of a position: distance to the nearest obstacle voxel's near side.
    auto clear = [&](const Eigen::Vector2d& q) {
      double d = INFINITY;
      for (const Eigen::Vector2d& o : obstacles) d = std::min(d, (o - q).norm());
      return d - 0.5 * s;
    };
    const double c0 = clear(p.head<2>());
    if (c0 >= keep) continue;
    // Max-min clearance within max_shift_m (up to `keep`: more is of no use), small moves
    // preferred; candidates in order of that score until one lands on support.
    cands.clear();
    for (int ix = -rs; ix <= rs; ++ix)
      for (int iy = -rs; iy <= rs; ++iy) {
        const Eigen::Vector2d off(ix * opt.sample_m, iy * opt.sample_m);
        if (off.norm() > opt.max_shift_m + 1e-9) continue;
        const double score = std::min(clear(p.head<2>() + off), keep) - 0.2 * off.norm();
        cands.push_back({-score, off});
      }
    std::sort(cands.begin(), cands.end(),
              [](const auto& a, const auto& b) { return a.first < b.first; });
    const double score0 = std::min(c0, keep);
    for (const auto& [neg, off] : cands) {
      if (-neg <= score0 + 1e-9) break;  // no better than staying
      Eigen::Vector3d q = p;
      q.head<2>() += off;
      q.z() += grade.dot(off);
      const auto sp = view.support_surface_near(q.cast<float>(), r.step_height_m);
      if (!sp || !(sp->reachable || sp->state == map::TravState::kTraversable ||
                   sp->state == map::TravState::kUnobserved))
        continue;
      q.z() = sp->height_m;
      points[i] = q;
      ++st.moved;
      st.max_shift_m = std::max(st.max_shift_m, off.norm());
      break;
    }
  }
  return st;
}

namespace {

bool clear_disc(const map::MapView& view, const Eigen::Vector2d& c, double h, double radius) {
  const double s = view.voxel_size_m();
  const int rv = int(std::ceil(radius / s));
  const int32_t cx = int32_t(std::floor(c.x() / s)), cy = int32_t(std::floor(c.y() / s));
  for (int dx = -rv; dx <= rv; ++dx)
    for (int dy = -rv; dy <= rv; ++dy)
      if ((dx * dx + dy * dy) * s * s <= radius * radius && obstacle_at(view, cx + dx, cy + dy, h))
        return false;
  return true;
}

// Height change of the support `dist` ahead of p along d (nearest to the expected height on a
// 30 deg flight), or NaN if there is none.
double gain_along(const map::MapView& view, const Eigen::Vector3d& p, const Eigen::Vector2d& d,
                  double dist, double sign) {
  const Eigen::Vector2d q = p.head<2>() + dist * d;
  const double expect = p.z() + sign * dist * 0.58;
  const auto sp = view.support_surface_near(
      Eigen::Vector3f(float(q.x()), float(q.y()), float(expect)), 0.5 * dist * 0.58 + 0.1);
  return sp ? double(sp->height_m) - p.z() : NAN;
}

}  // namespace

// The flight's axis at its foot p: the direction of travel (within 60 deg of the path's own
// direction `hint`) along which the support rises (sign +1) or falls (-1) the most over the next
// 0.6 and 0.9 m; the weighted mean of the directions within 80 % of the best gain, so a 1.2 m
// wide flight reads as its axis rather than a diagonal. Then the axis line is moved sideways to
// the middle between the side walls (or the body's half width + margin off a single wall).
std::optional<FlightAxis> flight_axis(const map::MapView& view, const Eigen::Vector3d& foot,
                                      const Eigen::Vector2d& hint, double sign) {
  constexpr int kDirs = 72;
  double gains[kDirs];
  auto dir_of = [](int k) {
    const double th = 2.0 * M_PI * k / kDirs;
    return Eigen::Vector2d(std::cos(th), std::sin(th));
  };
  for (int k = 0; k < kDirs; ++k) {
    const Eigen::Vector2d d = dir_of(k);
    const double g1 = sign * gain_along(view, foot, d, 0.6, sign);
    const double g2 = sign * gain_along(view, foot, d, 0.9, sign);
    gains[k] = g1 > 0 && g2 > 0 ? g1 + g2 : 0.0;  // NaN or not climbing: 0
  }
  // Best direction within 60 deg of the hint; then the gain-weighted mean of the directions
  // within 80 % of its gain and 70 deg of it, on both sides (the gain is symmetric about the
  // axis of a straight flight).
  int best_k = -1;
  for (int k = 0; k < kDirs; ++k)
    if (dir_of(k).dot(hint) >= 0.5 && gains[k] > 0 && (best_k < 0 || gains[k] > gains[best_k]))
      best_k = k;
  if (best_k < 0) return std::nullopt;
  const double best = gains[best_k];
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  for (int k = 0; k < kDirs; ++k)
    if (gains[k] >= 0.8 * best && dir_of(k).dot(dir_of(best_k)) >= std::cos(70 * M_PI / 180))
      sum += gains[k] * dir_of(k);
  if (sum.norm() < 1e-9) return std::nullopt;
  FlightAxis a;
  a.dir = sum.normalized();
  a.origin = foot.head<2>();
  // The risers face along the axis: where the map holds step edges ahead (their points are the
  // risers), the mean of their normals is the axis. The height gains above are only a first
  // guess: a side of the flight seen less well biases them toward the other side wall.
  {
    const double s = view.voxel_size_m();
    const Eigen::Vector2d nrm(-a.dir.y(), a.dir.x());
    const double z_lo = sign > 0 ? foot.z() - s : foot.z() - 1.0;
    const double z_hi = sign > 0 ? foot.z() + 1.0 : foot.z() + s;
    Eigen::Vector2d risers = Eigen::Vector2d::Zero();
    int n = 0;
    for (double t = 0.0; t <= 1.2; t += s)
      for (double l = -0.6; l <= 0.6; l += s) {
        const Eigen::Vector2d q = foot.head<2>() + t * a.dir + l * nrm;
        const int32_t cx = int32_t(std::floor(q.x() / s)), cy = int32_t(std::floor(q.y() / s));
        for (int32_t cz = int32_t(std::floor(z_lo / s)); cz <= int32_t(std::floor(z_hi / s));
             ++cz) {
          const auto rn = view.riser_normal({cx, cy, cz});
          if (!rn) continue;
          Eigen::Vector2d d = rn->cast<double>();
          if (d.dot(a.dir) < 0) d = -d;
          if (d.dot(a.dir) < std::cos(M_PI / 4)) continue;  // a side wall's top, not a riser
          risers += d;
          ++n;
        }
      }
    if (n >= 4) a.dir = risers.normalized();
  }
  // Centre the axis between the flight's side walls, measured 0.6 m up the flight at the
  // level of the support there.
  const RobotModel& r = view.robot();
  const Eigen::Vector2d nrm(-a.dir.y(), a.dir.x());
  const Eigen::Vector2d probe = foot.head<2>() + 0.6 * a.dir;
  const auto sp = view.support_surface_near(
      Eigen::Vector3f(float(probe.x()), float(probe.y()), float(foot.z() + sign * 0.35)), 0.3);
  const double h = sp ? double(sp->height_m) : foot.z() + sign * 0.35;
  const double s = view.voxel_size_m();
  auto side = [&](double sgn) {
    for (double t = 0.5 * s; t <= 1.0; t += 0.5 * s) {
      const Eigen::Vector2d q = probe + sgn * t * nrm;
      if (obstacle_at(view, int32_t(std::floor(q.x() / s)), int32_t(std::floor(q.y() / s)), h))
        return t;
    }
    return double(INFINITY);
  };
  const double left = side(1), right = side(-1);
  const double half_w = 0.5 * r.body_width_m + r.body_margin_m;
  double shift = 0;
  if (std::isfinite(left) && std::isfinite(right))
    shift = 0.5 * (left - right);
  else if (std::isfinite(left) && left < half_w + 0.1)
    shift = -(half_w + 0.1 - left);
  else if (std::isfinite(right) && right < half_w + 0.1)
    shift = half_w + 0.1 - right;
  a.origin += std::clamp(shift, -0.4, 0.4) * nrm;
  a.width_m = left + right;
  return a;
}

std::optional<FlightFoot> flight_foot(const map::MapView& view,
                                      const std::vector<Eigen::Vector3d>& near, double floor_z,
                                      double back_m, double radius_m, double run_up_m,
                                      bool sparse) {
  if (near.empty() || !std::isfinite(floor_z)) return std::nullopt;
  const RobotModel& r = view.robot();
  const double s = view.voxel_size_m(), step = r.step_height_m;
  const auto height_at = [&](const Eigen::Vector2d& q, double z, double window) {
    const auto sp =
        view.support_surface_near(Eigen::Vector3f(float(q.x()), float(q.y()), float(z)), window);
    return sp ? double(sp->height_m) : NAN;
  };
  // The first riser's points: columns holding the first tread (a step above the floor) with the
  // floor behind them and a higher tread ahead, in one of 8 directions. (The map's step edges,
  // VoxelStats::kStepEdge, mark few of a riser's voxels seen from the floor; the floor just before
  // a flight is often unseen: the LiDAR's blind ring around the robot at its viewpoint.)
  struct Edge {
    Eigen::Vector2d p, n;
    double d;
  };
  std::vector<Edge> edges;
  Eigen::Vector2d lo = near.front().head<2>(), hi = lo;
  for (const Eigen::Vector3d& q : near) {
    lo = lo.cwiseMin(q.head<2>());
    hi = hi.cwiseMax(q.head<2>());
  }
  const auto cell = [&](double v) { return int32_t(std::floor(v / s)); };
  for (int32_t kx = cell(lo.x() - radius_m); kx <= cell(hi.x() + radius_m); ++kx)
    for (int32_t ky = cell(lo.y() - radius_m); ky <= cell(hi.y() + radius_m); ++ky) {
      const Eigen::Vector2d q((kx + 0.5) * s, (ky + 0.5) * s);
      double d = INFINITY;
      for (const Eigen::Vector3d& p : near) d = std::min(d, (p.head<2>() - q).norm());
      if (d > radius_m) continue;
      const double t1 = height_at(q, floor_z + 0.9 * step, 0.45 * step);
      if (!(t1 > floor_z + 0.5 * step)) continue;
      for (int k = 0; k < 8; ++k) {
        const Eigen::Vector2d u(std::cos(k * M_PI / 4), std::sin(k * M_PI / 4));
        bool ground = false, t2 = false;
        for (double b = 0.15; b <= 0.8 + 1e-9 && !ground; b += 0.1)
          ground = std::abs(height_at(q - b * u, floor_z, 0.5 * step) - floor_z) < 0.5 * step;
        for (double a = 0.2; a <= 0.45 + 1e-9 && !t2 && ground; a += 0.1)
          t2 = height_at(q + a * u, t1 + 0.9 * step, 0.45 * step) > t1 + 0.5 * step;
        if (!t2) continue;
        edges.push_back({q - 0.5 * s * u, u, d});
      }
    }
  if (edges.empty()) return std::nullopt;
  // The riser line: the points facing one way (or, with `neighbours`, its way or one 45 deg
  // from it) within 0.2 m across and 1.5 m along a line through one of them, the line with the
  // most (ties: nearest the cluster); its middle c and normal up (the principal axis of its
  // points: the 8 search directions are 45 deg apart). False: fewer than 3 points.
  const auto line_of = [&](const Edge& e0, double min_dot, std::vector<Eigen::Vector2d>* pts) {
    const Eigen::Vector2d t0(-e0.n.y(), e0.n.x());
    int n = 0;
    for (const Edge& e : edges) {
      const Eigen::Vector2d dp = e.p - e0.p;
      if (e.n.dot(e0.n) < min_dot || std::abs(dp.dot(e0.n)) > 0.2 || std::abs(dp.dot(t0)) > 1.5)
        continue;
      if (pts) pts->push_back(e.p);
      ++n;
    }
    return n;
  };
  Eigen::Vector2d c, up;
  const Edge* best = nullptr;
  const auto riser = [&](bool neighbours) {
    const double min_dot = neighbours ? 0.7 : 0.99;
    int best_n = 0;
    for (const Edge& e : edges) {
      const int n = line_of(e, min_dot, nullptr);
      if (n > best_n || (n == best_n && e.d < best->d)) best = &e, best_n = n;
    }
    std::vector<Eigen::Vector2d> line;
    if (line_of(*best, min_dot, &line) < 3) return false;
    c = Eigen::Vector2d::Zero();
    for (const Eigen::Vector2d& p : line) c += p;
    c /= double(line.size());
    double sxx = 0, sxy = 0, syy = 0;
    for (const Eigen::Vector2d& p : line) {
      const Eigen::Vector2d d = p - c;
      sxx += d.x() * d.x(), sxy += d.x() * d.y(), syy += d.y() * d.y();
    }
    const double th = 0.5 * std::atan2(2.0 * sxy, sxx - syy);  // the riser's own direction
    up = Eigen::Vector2d(-std::sin(th), std::cos(th));
    if (up.dot(best->n) < 0) up = -up;
    return true;
  };
  if (!riser(false)) return std::nullopt;
  // A riser faces within 22.5 deg of one search direction. Its line found in another (a riser
  // seen sparsely passes for a diagonal direction more often than for its own: the return flight
  // of a U-shaped stair seen from its landing, teaching_building seed 1, session 24): found again
  // with each direction's neighbours counted in.
  if (sparse && up.dot(best->n) < std::cos(M_PI / 8) && !riser(true)) return std::nullopt;
  if (up.dot(best->n) < std::cos(M_PI / 4)) return std::nullopt;  // not a line across the search
  // The axis: flight_axis's (its direction from the tread heights and the risers' normals, its
  // line centred between the side walls) where it agrees with the riser's normal within 25 deg;
  // else (the heights of a flight seen from one side bias it) the riser's normal through its
  // middle.
  const Eigen::Vector2d f2 = c - back_m * up;
  const double fz = height_at(f2, floor_z, 0.5 * step);
  const auto found = flight_axis(view, {f2.x(), f2.y(), std::isfinite(fz) ? fz : floor_z}, up, 1.0);
  if (!found) return std::nullopt;  // no rise along it: not a flight
  FlightAxis a = *found;
  if (found->dir.dot(up) < std::cos(25 * M_PI / 180)) {  // biased: the riser's own line
    a.dir = up;
    a.origin = c;
    a.width_m = INFINITY;
  }
  // Where to stand: the point on the axis nearest the riser, at least back_m before it, on floor
  // the robot can walk to (in C_reach).
  const double t_riser = (c - a.origin).dot(a.dir);
  std::optional<map::SurfacePoint> sp;
  Eigen::Vector2d foot2;
  for (double b = back_m; b <= back_m + run_up_m + 1e-9 && !sp; b += 0.5 * s) {
    foot2 = a.origin + (t_riser - b) * a.dir;
    sp = view.support_surface_near(
        Eigen::Vector3f(float(foot2.x()), float(foot2.y()), float(floor_z)), 0.5 * step);
    if (sp && !sp->reachable) sp.reset();  // Stage 3's voxel A* walks C_reach
  }
  if (!sp) return std::nullopt;
  FlightFoot out;
  out.foot_m = {foot2.x(), foot2.y(), double(sp->height_m)};
  out.yaw_rad = std::atan2(a.dir.y(), a.dir.x());
  out.axis = a;
  out.riser_m = {c.x(), c.y(), floor_z};
  return out;
}

FlightShaping shape_flights(const map::MapView& view, std::vector<Eigen::Vector3d>& points) {
  FlightShaping out;
  const RobotModel& r = view.robot();
  const double s = view.voxel_size_m();
  const double run_up = 0.5 * r.body_length_m + r.body_margin_m;
  const double half_w = 0.5 * r.body_width_m + r.body_margin_m;
  const double level = 0.5 * r.step_height_m;
  for (size_t j = 1; j + 1 < points.size(); ++j) {
    if (!flight_step(r, points[j], points[j + 1], s)) continue;
    const double sign = points[j + 1].z() > points[j].z() ? 1.0 : -1.0;
    // The flight's extent in the path: it ends where the path stays level for a run-up.
    size_t e = j + 1, level_from = j + 1;
    while (e + 1 < points.size()) {
      if (flight_step(r, points[e], points[e + 1], s))
        level_from = e + 1;
      else if ((points[e + 1] - points[level_from]).head<2>().norm() >= run_up)
        break;
      ++e;
    }
    const bool ends_on_flight = e + 1 == points.size() && level_from + 1 >= e;
    const size_t end = std::min(level_from, points.size() - 1);
    Eigen::Vector2d hint = (points[end] - points[j]).head<2>();
    if (hint.norm() < 0.2) {
      j = e;
      continue;
    }
    const auto axis = flight_axis(view, points[j], hint.normalized(), sign);
    if (!axis) {
      ++out.no_axis;
      j = e;
      continue;
    }
    // Foot of the flight on the axis; the run-up behind it on the lower level.
    auto on_axis = [&](const Eigen::Vector2d& q) {
      return axis->origin + axis->dir * (q - axis->origin).dot(axis->dir);
    };
    const Eigen::Vector2d foot2 = on_axis(points[j].head<2>());
    const Eigen::Vector2d ru2 = foot2 - run_up * axis->dir;
    const auto ru_sp = view.support_surface_near(
        Eigen::Vector3f(float(ru2.x()), float(ru2.y()), float(points[j].z())), level);
    const bool run_up_ok = ru_sp &&
                           (ru_sp->reachable || ru_sp->state == map::TravState::kTraversable) &&
                           clear_disc(view, ru2, ru_sp->height_m, half_w);
    // The robot stands on the flight (or at its foot): there is no room for a run-up behind it,
    // and the flight is laid on its axis from here (else the raw path hugs a side wall).
    // (Experimental, with the blind climb: MapOptions::pool_short_risers is its map side.)
    const bool from_start =
        view.options().pool_short_risers && (points[j] - points[0]).head<2>().norm() < run_up + s;
    if (!run_up_ok && !from_start) {
      ++out.no_run_up;
      j = e;
      continue;
    }
    // The flight's points along the axis, from the foot to the projection of its last point.
    const double s_end = (points[end].head<2>() - foot2).dot(axis->dir);
    std::vector<Eigen::Vector3d> line;
    if (run_up_ok) line.emplace_back(ru2.x(), ru2.y(), ru_sp->height_m);
    const int n = std::max(1, int(std::ceil(s_end / s)));
    double z_prev = points[j].z();
    for (int i = 0; i <= n; ++i) {
      const double t = std::min(s_end, i * s);
      const Eigen::Vector2d q = foot2 + t * axis->dir;
      const double expect =
          points[j].z() + (points[end].z() - points[j].z()) * (t / std::max(s_end, 1e-6));
      // The foot stands on the lower level: the riser's smear in the column in front of it can
      // read a tread higher.
      const auto sp =
          view.support_surface_near(Eigen::Vector3f(float(q.x()), float(q.y()), float(expect)),
                                    i == 0 ? level : r.step_height_m);
      const double z = sp && std::abs(double(sp->height_m) - z_prev) <= r.step_height_m + 0.03
                           ? double(sp->height_m)
                           : expect;
      line.emplace_back(q.x(), q.y(), z);
      z_prev = z;
    }
    // Replace the approach within a run-up of the foot, the flight, and its last point.
    size_t first = j;
    while (run_up_ok && first > 1 && (points[first - 1] - points[j]).head<2>().norm() < run_up)
      --first;
    points.erase(points.begin() + long(first), points.begin() + long(end) + 1);
    points.insert(points.begin() + long(first), line.begin(), line.end());
    ++out.flights;
    if (ends_on_flight && first + line.size() == points.size()) {
      out.end_on_flight = true;
      out.end_yaw_rad = std::atan2(axis->dir.y(), axis->dir.x());
    }
    j = first + line.size() - 1;
  }
  return out;
}

double shape_path(const map::MapView& view, std::vector<Eigen::Vector3d>& points, double goal_yaw) {
  const FlightShaping f = shape_flights(view, points);
  centre_path(view, points);
  return f.end_on_flight ? f.end_yaw_rad : goal_yaw;
}

}  // namespace storey::core::plan
