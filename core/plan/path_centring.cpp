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
    const int32_t cx = int32_t(std::floor(p.x() / s)), cy = int32_t(std::floor(p.y() / s));
    // Obstacle columns around the point, at its own level (stairs: each tread has its own band).
    obstacles.clear();
    for (int dx = -rv; dx <= rv; ++dx)
      for (int dy = -rv; dy <= rv; ++dy)
        if ((dx * dx + dy * dy) * s * s <= reach * reach &&
            obstacle_at(view, cx + dx, cy + dy, p.z()))
          obstacles.emplace_back((cx + dx + 0.5) * s, (cy + dy + 0.5) * s);
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

int align_before_climbs(const map::MapView& view, std::vector<Eigen::Vector3d>& points,
                        double climb_look_m) {
  const RobotModel& r = view.robot();
  const double s = view.voxel_size_m();
  const double run_up = 0.5 * r.body_length_m + r.body_margin_m;
  const double half_w = 0.5 * r.body_width_m + r.body_margin_m;
  int inserted = 0;
  for (size_t j = 1; j + 1 < points.size(); ++j) {
    if (std::abs(points[j + 1].z() - points[j].z()) <= 0.5 * r.step_height_m) continue;
    // Level change between j and j + 1: the flight's direction from j over the next metre.
    size_t k = j + 1;
    while (k + 1 < points.size() && (points[k] - points[j]).head<2>().norm() < climb_look_m) ++k;
    Eigen::Vector2d dir = (points[k] - points[j]).head<2>();
    if (dir.norm() < 0.5 * climb_look_m) continue;
    dir.normalize();
    const Eigen::Vector2d q2 = points[j].head<2>() - run_up * dir;
    const auto sp = view.support_surface_near(
        Eigen::Vector3f(float(q2.x()), float(q2.y()), float(points[j].z())), 0.5 * r.step_height_m);
    if (!sp || !(sp->reachable || sp->state == map::TravState::kTraversable)) continue;
    bool clear = true;
    const int rv = int(std::ceil(half_w / s));
    const int32_t cx = int32_t(std::floor(q2.x() / s)), cy = int32_t(std::floor(q2.y() / s));
    for (int dx = -rv; dx <= rv && clear; ++dx)
      for (int dy = -rv; dy <= rv && clear; ++dy)
        if ((dx * dx + dy * dy) * s * s <= half_w * half_w)
          clear = !obstacle_at(view, cx + dx, cy + dy, sp->height_m);
    if (!clear) continue;
    // Drop the points of the approach that lie within the run-up (they would turn the body
    // there), keep the start, put the run-up point in their place.
    size_t first = j;
    while (first > 1 && (points[first - 1] - points[j]).head<2>().norm() < run_up) --first;
    points.erase(points.begin() + long(first), points.begin() + long(j));
    points.insert(points.begin() + long(first), Eigen::Vector3d(q2.x(), q2.y(), sp->height_m));
    ++inserted;
    // Skip the rest of the flight: it ends where the path stays level for a run-up's length.
    j = first + 1;
    size_t level_from = j;
    while (j + 1 < points.size()) {
      if (std::abs(points[j + 1].z() - points[j].z()) > 0.5 * r.step_height_m)
        level_from = j + 1;
      else if ((points[j + 1] - points[level_from]).head<2>().norm() >= run_up)
        break;
      ++j;
    }
  }
  return inserted;
}

}  // namespace storey::core::plan
