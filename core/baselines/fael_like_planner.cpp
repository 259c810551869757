#include "core/baselines/fael_like_planner.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <queue>

namespace storey::core::baselines {

void TraversabilityGrid2D::build(const map::MapView& view, double floor_z_m, double band_m,
                                 double obstacle_from_m, double body_top_m) {
  res_ = view.voxel_size_m();
  floor_z_ = floor_z_m;
  struct Mark {
    map::VoxelKey k;
    GridCell c;
    float h;
  };
  std::vector<Mark> marks;
  const double elevation_top_m = std::max(body_top_m, 1.8);  // below any ceiling of a storey
  const double lo = floor_z_m - band_m - res_, hi = floor_z_m + elevation_top_m;
  view.for_each_occupied([&](const map::VoxelKey& k, const map::Cell&, const auto*) {
    const double zc = (k.z + 0.5) * res_;
    if (zc < lo || zc > hi) return;
    if (view.is_support(k)) {
      const float h = view.surface_height_m(k).value_or(float(zc));
      if (std::abs(h - floor_z_m) <= band_m) {
        // On the floor's plane: free where traversable; under-observed ground stays unknown (a
        // frontier); an untraversable support (too rough, too close to a wall) is an obstacle.
        const map::TravState st = view.state(k);
        if (st == map::TravState::kUnobserved) return;
        marks.push_back(
            {k, st == map::TravState::kTraversable ? GridCell::kFree : GridCell::kObstacle, h});
        return;
      }
      // A surface above the band: an elevation change (a stair tread, a ramp past the band, a
      // landing), an obstacle of the plane up to elevation_top.
      if (h > floor_z_m + obstacle_from_m && h <= floor_z_m + elevation_top_m) {
        marks.push_back({k, GridCell::kObstacle, h});
        return;
      }
    }
    // Anything else between the obstacle threshold and the body top: walls, furniture.
    if (zc > floor_z_m + obstacle_from_m && zc <= floor_z_m + body_top_m)
      marks.push_back({k, GridCell::kObstacle, float(zc)});
  });
  nx_ = ny_ = 0;
  cells_.clear();
  heights_.clear();
  if (marks.empty()) return;
  int minx = marks[0].k.x, maxx = minx, miny = marks[0].k.y, maxy = miny;
  for (const Mark& m : marks) {
    minx = std::min(minx, m.k.x), maxx = std::max(maxx, m.k.x);
    miny = std::min(miny, m.k.y), maxy = std::max(maxy, m.k.y);
  }
  x0_ = minx - 1, y0_ = miny - 1;  // one unknown cell of margin on every side
  nx_ = maxx - minx + 3, ny_ = maxy - miny + 3;
  cells_.assign(size_t(nx_) * size_t(ny_), GridCell::kUnknown);
  heights_.assign(cells_.size(), float(floor_z_m));
  for (const Mark& m : marks) {
    const size_t i = size_t(m.k.y - y0_) * size_t(nx_) + size_t(m.k.x - x0_);
    if (m.c == GridCell::kObstacle) {
      cells_[i] = GridCell::kObstacle;  // obstacle wins over a free surface below it
    } else if (cells_[i] != GridCell::kObstacle) {
      if (cells_[i] != GridCell::kFree ||
          std::abs(m.h - floor_z_m) < std::abs(heights_[i] - floor_z_m))
        heights_[i] = m.h;
      cells_[i] = GridCell::kFree;
    }
  }
}

FaelLikePlanner::FaelLikePlanner(const RobotModel& robot, const plan::PlanOptions& plan,
                                 double voxel_size_m, const BaselineOptions& options)
    : robot_(robot), opt_(options), driver_(robot, plan, voxel_size_m, options) {}

std::vector<Goal> FaelLikePlanner::goals(const plan::ExplorationInput& in) {
  std::vector<Goal> out;
  if (!have_floor_) floor_z_ = in.robot_foot_m.z(), have_floor_ = true;
  grid_.build(*in.view, floor_z_, opt_.fael_band_m, opt_.fael_obstacle_from_m,
              robot_.body_height_m + robot_.body_margin_m);
  const int nx = grid_.nx(), ny = grid_.ny();
  if (nx == 0) return out;
  const double res = grid_.resolution();
  const size_t n = size_t(nx) * size_t(ny);
  // Inflation: hard at half the body width + margin, soft (cost x2) at half its length.
  const int hard = int(std::ceil((robot_.body_width_m / 2 + robot_.body_margin_m) / res));
  const int soft = int(std::ceil((robot_.body_length_m / 2 + robot_.body_margin_m) / res));
  blocked_.assign(n, 0);
  near_.assign(n, 0);
  for (int y = 0; y < ny; ++y)
    for (int x = 0; x < nx; ++x) {
      if (grid_.at(x, y) != GridCell::kObstacle) continue;
      for (int dy = -soft; dy <= soft; ++dy)
        for (int dx = -soft; dx <= soft; ++dx) {
          if (!grid_.inside(x + dx, y + dy) || dx * dx + dy * dy > soft * soft) continue;
          const size_t i = size_t(y + dy) * size_t(nx) + size_t(x + dx);
          near_[i] = 1;
          if (dx * dx + dy * dy <= hard * hard) blocked_[i] = 1;
        }
    }
  // Dijkstra on the plane from the robot's cell (8-connected; the start cell and its first ring
  // pass even when inflated: the robot already stands there).
  const int sx = grid_.ix_of(in.robot_foot_m.x()), sy = grid_.iy_of(in.robot_foot_m.y());
  if (!grid_.inside(sx, sy)) return out;
  dist_.assign(n, std::numeric_limits<double>::infinity());
  parent_.assign(n, -1);
  auto passable = [&](int x, int y) {
    if (!grid_.inside(x, y) || grid_.at(x, y) != GridCell::kFree) return false;
    const bool start_ring = std::abs(x - sx) <= 2 && std::abs(y - sy) <= 2;
    return start_ring || !blocked_[size_t(y) * size_t(nx) + size_t(x)];
  };
  using Item = std::pair<double, int32_t>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> q;
  const int32_t s = sy * nx + sx;
  dist_[size_t(s)] = 0;
  q.push({0, s});
  // The robot's own cell may read as an obstacle of the plane: a table top the robot walked
  // under, seen once it was there, is an elevation change to the 2.5D projection
  // (teaching_building: "complete" at 35 s in the first classroom). It walks out first, straight
  // to the nearest free, uninflated cell within kExitM (its trajectory is FCL-checked like any).
  const bool walk_out = grid_.at(sx, sy) != GridCell::kFree;
  if (walk_out) {
    constexpr double kExitM = 1.0;
    const int r = int(std::ceil(kExitM / res));
    int32_t exit = -1;
    double exit_d = std::numeric_limits<double>::infinity();
    for (int dy = -r; dy <= r; ++dy)
      for (int dx = -r; dx <= r; ++dx) {
        const int x = sx + dx, y = sy + dy;
        const double d = res * std::hypot(dx, dy);
        if (d > kExitM || d >= exit_d || !grid_.inside(x, y) || grid_.at(x, y) != GridCell::kFree ||
            blocked_[size_t(y) * size_t(nx) + size_t(x)])
          continue;
        exit_d = d, exit = y * nx + x;
      }
    if (exit >= 0) {
      dist_[size_t(exit)] = exit_d;
      parent_[size_t(exit)] = s;
      q.push({exit_d, exit});
    }
  }
  while (!q.empty()) {
    const auto [d, u] = q.top();
    q.pop();
    if (d > dist_[size_t(u)]) continue;
    const int ux = u % nx, uy = u / nx;
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        if (!dx && !dy) continue;
        const int vx = ux + dx, vy = uy + dy;
        if (!passable(vx, vy)) continue;
        if (dx && dy && !(passable(ux + dx, uy) && passable(ux, uy + dy))) continue;  // corners
        const int32_t v = vy * nx + vx;
        const double step = res * ((dx && dy) ? M_SQRT2 : 1.0) * (near_[size_t(v)] ? 2.0 : 1.0);
        if (d + step < dist_[size_t(v)]) {
          dist_[size_t(v)] = d + step;
          parent_[size_t(v)] = u;
          q.push({d + step, v});
        }
      }
  }
  // Frontier cells: free cells with an unknown 4-neighbour; clustered 8-connected on the plane.
  std::vector<uint8_t> frontier(n, 0), seen(n, 0);
  static constexpr int kDx[4] = {1, -1, 0, 0}, kDy[4] = {0, 0, 1, -1};
  for (int y = 0; y < ny; ++y)
    for (int x = 0; x < nx; ++x) {
      if (grid_.at(x, y) != GridCell::kFree) continue;
      for (int k = 0; k < 4; ++k)
        if (grid_.at(x + kDx[k], y + kDy[k]) == GridCell::kUnknown)
          frontier[size_t(y * nx + x)] = 1;
    }
  std::vector<int32_t> stack, members;
  for (int32_t c0 = 0; c0 < int32_t(n); ++c0) {
    if (!frontier[size_t(c0)] || seen[size_t(c0)]) continue;
    members.clear();
    stack.assign(1, c0);
    seen[size_t(c0)] = 1;
    Eigen::Vector2d centroid = Eigen::Vector2d::Zero(), unknown = Eigen::Vector2d::Zero();
    while (!stack.empty()) {
      const int32_t u = stack.back();
      stack.pop_back();
      members.push_back(u);
      const int ux = u % nx, uy = u / nx;
      centroid += grid_.centre(ux, uy);
      for (int k = 0; k < 4; ++k)
        if (grid_.at(ux + kDx[k], uy + kDy[k]) == GridCell::kUnknown)
          unknown += Eigen::Vector2d(kDx[k], kDy[k]);
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int vx = ux + dx, vy = uy + dy;
          if (!grid_.inside(vx, vy)) continue;
          const int32_t v = vy * nx + vx;
          if (frontier[size_t(v)] && !seen[size_t(v)]) seen[size_t(v)] = 1, stack.push_back(v);
        }
    }
    if (int(members.size()) < opt_.min_cluster_cells) continue;
    centroid /= double(members.size());
    // Viewpoint: the reachable cell nearest the centroid among the members and the cells within
    // 0.5 m of them (a frontier hugging a wall is seen from the inflated-free cells beside it).
    const int r = int(std::ceil(0.5 / res));
    int32_t best = -1;
    double best_d = std::numeric_limits<double>::infinity();
    for (int32_t u : members) {
      const int ux = u % nx, uy = u / nx;
      for (int dy = -r; dy <= r; dy += 1)
        for (int dx = -r; dx <= r; dx += 1) {
          const int vx = ux + dx, vy = uy + dy;
          if (!grid_.inside(vx, vy)) continue;
          const int32_t v = vy * nx + vx;
          if (!std::isfinite(dist_[size_t(v)])) continue;
          const double d = (grid_.centre(vx, vy) - centroid).squaredNorm();
          if (d < best_d) best_d = d, best = v;
        }
    }
    if (best < 0) continue;  // not reachable on the plane
    Goal g;
    const int bx = best % nx, by = best / nx;
    const Eigen::Vector2d c = grid_.centre(bx, by);
    g.p_m = Eigen::Vector3d(c.x(), c.y(), grid_.height(bx, by));
    g.key_m = Eigen::Vector3d(centroid.x(), centroid.y(), floor_z_);
    const Eigen::Vector2d look = unknown.norm() > 1e-9 ? unknown : (centroid - c);
    g.yaw_rad = look.norm() > 1e-9 ? std::atan2(look.y(), look.x()) : in.robot_yaw_rad;
    // FAEL-style utility gain / cost, as a cost to minimise.
    g.cost = -double(members.size()) / (1.0 + dist_[size_t(best)]);
    // The grid path (start -> viewpoint) as support points, every few cells.
    std::vector<Eigen::Vector3d> rev;
    int k = 0;
    for (int32_t u = best; u >= 0; u = parent_[size_t(u)], ++k) {
      const bool exit_step = walk_out && parent_[size_t(u)] == s;
      if (u != best && parent_[size_t(u)] >= 0 && !exit_step && k % 3) continue;
      const Eigen::Vector2d p = grid_.centre(u % nx, u / nx);
      rev.push_back({p.x(), p.y(), grid_.height(u % nx, u / nx)});
    }
    g.path_m.assign(rev.rbegin(), rev.rend());
    if (g.path_m.size() < 2) g.path_m.push_back(g.p_m);
    out.push_back(std::move(g));
  }
  return out;
}

plan::ExplorationResult FaelLikePlanner::plan(const plan::ExplorationInput& in) {
  plan::ExplorationResult r;
  if (!in.view || !in.robot_foot_m.allFinite() || !std::isfinite(in.t_s)) {
    r.reason = "bad input (null map or non-finite pose/time)";
    return r;
  }
  std::vector<Goal> gs = goals(in);
  r.floor = 0;  // one plane: the start floor
  if (driver_.keep(in, gs, r)) return r;
  driver_.choose(in, gs, r);
  return r;
}

}  // namespace storey::core::baselines
