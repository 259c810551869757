#include "core/baselines/nearest_frontier_planner.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <unordered_map>
#include <unordered_set>

namespace storey::core::baselines {

namespace {
uint64_t pack(const map::VoxelKey& k) {
  return (uint64_t(uint32_t(k.x) & 0x1FFFFF) << 42) | (uint64_t(uint32_t(k.y) & 0x1FFFFF) << 21) |
         uint64_t(uint32_t(k.z) & 0x1FFFFF);
}
// Column (x, y) has no known ground at level z (the robot's level there): no voxel from z - 1
// to z + 1 is occupied with a decided state, and either the ground there is under-observed
// (S_unobs, N(v) < N_min: seen by a few rays only, as at the edge of what the LiDAR reached) or
// nothing below the level was seen free. A VLP-16 leaves gaps between its rings on the floor:
// rays bound for the next ring graze the floor's own voxel (z) and carve it free, but none goes
// below it, so the ground there is unknown, not absent (maze seeds 2, 4, 5 ended "complete" at
// 4 s when a free voxel at z alone meant a drop). A drop is known only once a ray has passed
// below the level (z - 1 seen free); a wall is never a frontier.
bool unknown_column(const map::MapView& view, int32_t x, int32_t y, int32_t z) {
  bool unobserved = false;
  for (int32_t dz = -1; dz <= 1; ++dz) {
    const map::VoxelKey k{x, y, z + dz};
    if (view.occupancy(k) != map::Occupancy::kOccupied) continue;
    if (view.state(k) != map::TravState::kUnobserved) return false;
    unobserved = true;
  }
  return unobserved || view.occupancy(map::VoxelKey{x, y, z}) == map::Occupancy::kUnknown ||
         view.occupancy(map::VoxelKey{x, y, z - 1}) != map::Occupancy::kFree;
}
}  // namespace

std::vector<FrontierVoxelCluster> volumetric_frontiers(const map::MapView& view, int min_cells) {
  std::vector<map::VoxelKey> cells;
  std::unordered_map<uint64_t, Eigen::Vector2d> dir;
  view.for_each_occupied([&](const map::VoxelKey& k, const map::Cell&, const auto*) {
    if (!view.is_reachable(k) || !view.is_support(k)) return;
    Eigen::Vector2d d = Eigen::Vector2d::Zero();
    static constexpr int kDx[4] = {1, -1, 0, 0}, kDy[4] = {0, 0, 1, -1};
    for (int i = 0; i < 4; ++i)
      if (unknown_column(view, k.x + kDx[i], k.y + kDy[i], k.z))
        d += Eigen::Vector2d(kDx[i], kDy[i]);
    if (d.squaredNorm() == 0) return;
    cells.push_back(k);
    dir[pack(k)] = d;
  });
  // for_each_occupied walks a hash table: sort for a deterministic clustering order.
  std::sort(cells.begin(), cells.end(), [](const map::VoxelKey& a, const map::VoxelKey& b) {
    return std::tie(a.x, a.y, a.z) < std::tie(b.x, b.y, b.z);
  });
  std::unordered_set<uint64_t> left;
  for (const map::VoxelKey& k : cells) left.insert(pack(k));
  std::vector<FrontierVoxelCluster> out;
  std::vector<map::VoxelKey> stack;
  for (const map::VoxelKey& seed : cells) {
    if (!left.erase(pack(seed))) continue;
    FrontierVoxelCluster c;
    stack.assign(1, seed);
    while (!stack.empty()) {
      const map::VoxelKey k = stack.back();
      stack.pop_back();
      c.voxels.push_back(k);
      for (int dx = -1; dx <= 1; ++dx)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dz = -1; dz <= 1; ++dz) {
            const map::VoxelKey n{k.x + dx, k.y + dy, k.z + dz};
            if (left.erase(pack(n))) stack.push_back(n);
          }
    }
    if (int(c.voxels.size()) < min_cells) continue;
    for (const map::VoxelKey& k : c.voxels) {
      c.centroid_m += view.centre_of(k).cast<double>();
      c.unknown_dir += dir[pack(k)];
    }
    c.centroid_m /= double(c.voxels.size());
    out.push_back(std::move(c));
  }
  return out;
}

NearestFrontierPlanner::NearestFrontierPlanner(const RobotModel& robot,
                                               const plan::PlanOptions& plan, double voxel_size_m,
                                               const BaselineOptions& options)
    : opt_(options), driver_(robot, plan, voxel_size_m, options) {}

std::vector<Goal> NearestFrontierPlanner::goals(const plan::ExplorationInput& in) {
  std::vector<Goal> out;
  const map::MapView& view = *in.view;
  for (const FrontierVoxelCluster& c : volumetric_frontiers(view, opt_.min_cluster_cells)) {
    // Stand on the cluster's voxel nearest its centroid where the body fits (A* state).
    const map::VoxelKey* best = nullptr;
    double best_d = 1e18;
    for (const map::VoxelKey& k : c.voxels) {
      const auto h = view.surface_height_m(k);
      if (!h || !driver_.astar().passable(view, k, *h)) continue;
      const double d = (view.centre_of(k).cast<double>() - c.centroid_m).squaredNorm();
      if (d < best_d) best_d = d, best = &k;
    }
    Goal g;
    if (best) {
      const Eigen::Vector3f p = view.centre_of(*best);
      g.p_m = Eigen::Vector3d(p.x(), p.y(), view.surface_height_m(*best).value_or(p.z()));
    } else {
      // No member fits the body (a frontier along a wall): the reachable, passable support
      // within 0.5 m of a member nearest the centroid (a subsample of members: bounded work).
      bool found = false;
      const size_t stride = std::max<size_t>(1, c.voxels.size() / 16);
      for (size_t i = 0; i < c.voxels.size(); i += stride) {
        const Eigen::Vector3f m = view.centre_of(c.voxels[i]);
        for (int dx = -5; dx <= 5; ++dx)
          for (int dy = -5; dy <= 5; ++dy) {
            const Eigen::Vector3f q = m + Eigen::Vector3f(dx, dy, 0) * float(view.voxel_size_m());
            const auto sp = view.support_surface_near(q, 0.3);
            if (!sp || !sp->reachable || !driver_.astar().passable(view, sp->key, sp->height_m))
              continue;
            const Eigen::Vector3d at(q.x(), q.y(), sp->height_m);
            const double d = (at - c.centroid_m).squaredNorm();
            if (d < best_d) best_d = d, g.p_m = at, found = true;
          }
      }
      if (!found) continue;  // nowhere to stand near it
    }
    g.key_m = c.centroid_m;
    const Eigen::Vector2d d =
        c.unknown_dir.norm() > 1e-9 ? c.unknown_dir : (g.p_m - in.robot_foot_m).head<2>().eval();
    g.yaw_rad = d.norm() > 1e-9 ? std::atan2(d.y(), d.x()) : in.robot_yaw_rad;
    g.cost = (g.p_m - in.robot_foot_m).norm();  // straight line; refined by A* below
    out.push_back(std::move(g));
  }
  return out;
}

plan::ExplorationResult NearestFrontierPlanner::plan(const plan::ExplorationInput& in) {
  plan::ExplorationResult r;
  if (!in.view || !in.robot_foot_m.allFinite() || !std::isfinite(in.t_s)) {
    r.reason = "bad input (null map or non-finite pose/time)";
    return r;
  }
  std::vector<Goal> gs = goals(in);
  if (driver_.keep(in, gs, r)) return r;
  // Nearest by voxel A* path cost: the straight-line nearest few get an A* each and are ranked
  // by path cost (a frontier behind a wall is not near); the path found is reused by Stage 3.
  std::erase_if(gs, [&](const Goal& g) { return driver_.set_aside(g); });
  std::stable_sort(gs.begin(), gs.end(),
                   [](const Goal& a, const Goal& b) { return a.cost < b.cost; });
  constexpr size_t kRanked = 6;
  for (size_t i = 0; i < gs.size() && i < kRanked; ++i) {
    plan::VoxelPath vp = driver_.astar().plan(*in.view, in.robot_foot_m, gs[i].p_m);
    if (vp.status == plan::VoxelAStarStatus::kOk && !vp.points_m.empty()) {
      gs[i].cost = vp.cost;
      gs[i].path_m = std::move(vp.points_m);
    } else {
      gs[i].cost += 1e6;  // unreachable now: after every reachable one
    }
  }
  driver_.choose(in, gs, r);
  return r;
}

}  // namespace storey::core::baselines
