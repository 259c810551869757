#include "core/plan/voxel_astar.hpp"

#include <algorithm>
#include <cmath>
#include <functional>

namespace storey::core::plan {

namespace {
// A stair nosing's height (a step edge) reads up to kStepEdgeSlackM high: the next nosing one
// rise up must not read as an obstacle above the step height.
float edge_slack(const map::MapView& view, const map::VoxelKey& k) {
  return view.is_step_edge(k) ? map::kStepEdgeSlackM : 0.0f;
}
}  // namespace

namespace {
uint64_t pack(const map::VoxelKey& k) {
  constexpr uint64_t m = (uint64_t{1} << 21) - 1;
  return ((uint64_t(uint32_t(k.x)) & m) << 42) | ((uint64_t(uint32_t(k.y)) & m) << 21) |
         (uint64_t(uint32_t(k.z)) & m);
}
}  // namespace

const char* to_string(VoxelAStarStatus s) {
  switch (s) {
    case VoxelAStarStatus::kOk:
      return "ok";
    case VoxelAStarStatus::kBadInput:
      return "bad input (non-finite start or goal)";
    case VoxelAStarStatus::kNoStartSupport:
      return "no support surface under the start";
    case VoxelAStarStatus::kNoGoalSupport:
      return "no support surface under the goal";
    case VoxelAStarStatus::kGoalNotPassable:
      return "goal surface found but no passable state within the goal tolerance";
    case VoxelAStarStatus::kNoPath:
      return "no path: goal not connected through passable voxels";
    case VoxelAStarStatus::kExpansionLimit:
      return "expansion limit reached before the goal";
  }
  return "?";
}

bool VoxelAStar::passable(const map::MapView& view, const map::VoxelKey& k, float surface_h) const {
  const RobotModel& robot = view.robot();
  if (view.state(k) != map::TravState::kTraversable) return false;
  if (opt_.reachable_only && !view.is_reachable(k)) return false;
  const double body_top = robot.body_height_m + robot.body_margin_m;
  if (!view.is_free_above(k, body_top, opt_.unknown_is_free)) return false;
  // Horizontal clearance: occupied voxels between the step height and the body top.
  const double s = view.voxel_size_m();
  const double r = opt_.inflation_radius_m >= 0 ? opt_.inflation_radius_m
                                                : 0.5 * robot.body_width_m + robot.body_margin_m;
  const int rv = int(std::floor(r / s + 1e-9));
  // A voxel is an obstacle if its points' mean height is at least h + step (the voxel's own
  // surface height, not its centre: a tread top at a voxel boundary must not read 5 cm high).
  const double z_lo = surface_h + robot.step_height_m, z_hi = surface_h + body_top;
  const int32_t kz0 = int32_t(std::floor(z_lo / s)), kz1 = int32_t(std::floor(z_hi / s));
  for (int dx = -rv; dx <= rv; ++dx)
    for (int dy = -rv; dy <= rv; ++dy) {
      if ((dx * dx + dy * dy) * s * s > r * r + 1e-12) continue;
      for (int32_t z = kz0; z <= kz1; ++z) {
        const map::VoxelKey w{k.x + dx, k.y + dy, z};
        const auto zs = view.surface_height_m(w);
        if (zs && *zs - edge_slack(view, w) >= z_lo && *zs < z_hi) return false;
      }
    }
  return true;
}

bool VoxelAStar::near_obstacle(const map::MapView& view, const map::VoxelKey& k,
                               float surface_h) const {
  const RobotModel& robot = view.robot();
  const double s = view.voxel_size_m();
  const double soft = opt_.soft_radius_m >= 0 ? opt_.soft_radius_m
                                              : 0.5 * robot.body_length_m + robot.body_margin_m;
  const double hard = opt_.inflation_radius_m >= 0 ? opt_.inflation_radius_m
                                                   : 0.5 * robot.body_width_m + robot.body_margin_m;
  if (soft <= hard || opt_.clearance_weight <= 0) return false;
  const double z_lo = surface_h + robot.step_height_m;
  const double z_hi = surface_h + robot.body_height_m + robot.body_margin_m;
  const int32_t kz0 = int32_t(std::floor(z_lo / s)), kz1 = int32_t(std::floor(z_hi / s));
  const Eigen::Vector2d c((k.x + 0.5) * s, (k.y + 0.5) * s);
  for (const double r : {0.5 * (soft + hard), soft}) {
    for (int a = 0; a < 16; ++a) {
      const double th = a * (M_PI / 8);
      const int32_t x = int32_t(std::floor((c.x() + r * std::cos(th)) / s));
      const int32_t y = int32_t(std::floor((c.y() + r * std::sin(th)) / s));
      for (int32_t z = kz0; z <= kz1; ++z) {
        const auto zs = view.surface_height_m({x, y, z});
        if (zs && *zs - edge_slack(view, {x, y, z}) >= z_lo && *zs < z_hi) return true;
      }
    }
  }
  return false;
}

uint32_t VoxelAStar::neighbour(const map::MapView& view, int32_t x, int32_t y, float h) {
  const double s = view.voxel_size_m();
  const Eigen::Vector3f p(float((x + 0.5) * s), float((y + 0.5) * s), h);
  // Window widened by the step-edge slack; the step itself is checked in plan().
  const auto sp = view.support_surface_near(p, view.robot().step_height_m + map::kStepEdgeSlackM);
  if (!sp) return kNone;
  const uint64_t key = pack(sp->key);
  auto [it, fresh] = passable_.try_emplace(key, 0);
  if (fresh && passable(view, sp->key, sp->height_m))
    it->second = kPass | (near_obstacle(view, sp->key, sp->height_m) ? kNear : 0);
  if (!it->second) return kNone;
  auto [ni, created] = index_.try_emplace(key, uint32_t(nodes_.size()));
  if (created)
    nodes_.push_back({sp->key, sp->height_m, bool(it->second & kNear), INFINITY, kNone, false});
  return ni->second;
}

VoxelPath VoxelAStar::plan(const map::MapView& view, const Eigen::Vector3d& start_m,
                           const Eigen::Vector3d& goal_m) {
  VoxelPath out;
  if (!start_m.allFinite() || !goal_m.allFinite()) return out;
  nodes_.clear();
  index_.clear();
  passable_.clear();
  heap_.clear();
  const auto s_sp = view.support_surface_near(start_m.cast<float>(), opt_.snap_window_m);
  if (!s_sp) {
    out.status = VoxelAStarStatus::kNoStartSupport;
    return out;
  }
  const auto g_sp = view.support_surface_near(goal_m.cast<float>(), opt_.snap_window_m);
  if (!g_sp) {
    out.status = VoxelAStarStatus::kNoGoalSupport;
    return out;
  }
  const double s = view.voxel_size_m();
  const double step = view.robot().step_height_m;
  auto point = [&](const Node& n) {
    return Eigen::Vector3d((n.key.x + 0.5) * s, (n.key.y + 0.5) * s, n.h_m);
  };
  const Eigen::Vector3d goal_p((g_sp->key.x + 0.5) * s, (g_sp->key.y + 0.5) * s, g_sp->height_m);
  const double tol = std::max(opt_.goal_tolerance_m, 0.5 * s);
  auto at_goal = [&](const Eigen::Vector3d& p) {
    return (p - goal_p).head<2>().norm() <= tol + 1e-9 && std::abs(p.z() - goal_p.z()) <= step;
  };
  auto heuristic = [&](const Eigen::Vector3d& p) {
    return std::max(0.0, (p - goal_p).norm() - tol);
  };

  // The start is where the robot stands: accepted even if its clearance test fails (it may be
  // brushing a wall); every other state must pass.
  nodes_.push_back({s_sp->key, s_sp->height_m, false, 0.0, kNone, false});
  index_.emplace(pack(s_sp->key), 0);
  passable_.emplace(pack(s_sp->key), 1);
  heap_.push_back({heuristic(point(nodes_[0])), 0});
  bool goal_seen_passable = false;
  uint32_t reached = kNone;
  static constexpr int kDx[8] = {1, -1, 0, 0, 1, 1, -1, -1};
  static constexpr int kDy[8] = {0, 0, 1, -1, 1, -1, 1, -1};
  while (!heap_.empty()) {
    std::pop_heap(heap_.begin(), heap_.end(), std::greater<HeapItem>());
    const HeapItem top = heap_.back();
    heap_.pop_back();
    if (nodes_[top.node].closed) continue;
    nodes_[top.node].closed = true;
    const Node cur = nodes_[top.node];
    const Eigen::Vector3d cp = point(cur);
    if (at_goal(cp)) {
      reached = top.node;
      break;
    }
    if (out.expansions >= opt_.max_expansions) {
      out.status = VoxelAStarStatus::kExpansionLimit;
      return out;
    }
    ++out.expansions;
    uint32_t side[4];
    for (int d = 0; d < 8; ++d) {
      uint32_t nb;
      if (d < 4) {
        nb = side[d] = neighbour(view, cur.key.x + kDx[d], cur.key.y + kDy[d], cur.h_m);
      } else {
        // Diagonal: both side neighbours (x and y steps) must be passable.
        const uint32_t sx = side[kDx[d] > 0 ? 0 : 1], sy = side[kDy[d] > 0 ? 2 : 3];
        if (sx == kNone || sy == kNone) continue;
        nb = neighbour(view, cur.key.x + kDx[d], cur.key.y + kDy[d], cur.h_m);
      }
      if (nb == kNone) continue;
      Node& n = nodes_[nb];
      if (n.closed) continue;
      const Eigen::Vector3d np = point(n);
      // Nosing heights (step edges) are estimates up to kStepEdgeSlackM high.
      if (std::abs(np.z() - cp.z()) >
          step + std::max(edge_slack(view, n.key), edge_slack(view, cur.key)))
        continue;
      goal_seen_passable |= at_goal(np);
      const double w = (np - cp).norm() * (1.0 + opt_.cost_weight * view.cost(n.key) +
                                           (n.near ? opt_.clearance_weight : 0.0));
      const double g = cur.g + w;
      if (g < n.g) {
        n.g = g;
        n.parent = top.node;
        heap_.push_back({g + heuristic(np), nb});
        std::push_heap(heap_.begin(), heap_.end(), std::greater<HeapItem>());
      }
    }
  }
  if (reached == kNone) {
    // Tell "the goal's own surface is blocked" apart from "not connected".
    bool any_passable_near_goal = goal_seen_passable;
    if (!any_passable_near_goal) {
      const int rv = int(std::ceil(tol / s));
      for (int dx = -rv; dx <= rv && !any_passable_near_goal; ++dx)
        for (int dy = -rv; dy <= rv && !any_passable_near_goal; ++dy) {
          const Eigen::Vector3f p(float((g_sp->key.x + dx + 0.5) * s),
                                  float((g_sp->key.y + dy + 0.5) * s), g_sp->height_m);
          const auto sp = view.support_surface_near(p, step);
          if (sp && at_goal(Eigen::Vector3d(p.x(), p.y(), sp->height_m)) &&
              passable(view, sp->key, sp->height_m))
            any_passable_near_goal = true;
        }
    }
    out.status =
        any_passable_near_goal ? VoxelAStarStatus::kNoPath : VoxelAStarStatus::kGoalNotPassable;
    return out;
  }
  for (uint32_t i = reached; i != kNone; i = nodes_[i].parent) {
    out.keys.push_back(nodes_[i].key);
    out.points_m.push_back(point(nodes_[i]));
  }
  std::reverse(out.keys.begin(), out.keys.end());
  std::reverse(out.points_m.begin(), out.points_m.end());
  out.cost = nodes_[reached].g;
  out.status = VoxelAStarStatus::kOk;
  return out;
}

}  // namespace storey::core::plan
