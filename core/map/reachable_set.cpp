// TraversabilityMap: the connected reachable set C_reach (paper Sec. III-A, last paragraph).
//
// Adjacency: two traversable support voxels in 8-connected neighbouring columns, or one stride
// apart across a column with nothing standing in it (stride_clear), whose surface heights
// differ by at most the step height (slope is already bounded per voxel by c(v)); any
// number of floors can stack over one column. Maintenance is a dynamic BFS tree: every member
// stores its hop count from the root, and every member but the root has a neighbour with a
// smaller count. Growth adds voxels with parent count + 1. Removal (a member turned
// untraversable or lost its edge) orphans it and, transitively, every neighbour with a larger
// count that finds no other neighbour with a smaller one; then the orphans are regrown from
// the surviving boundary. Several roots (count 0) form a BFS forest: when the robot's seed is
// outside the set it becomes a new root. Losing a root orphans it like any member; a full
// regrow from the seed happens only when no root is left (or the root list is full).
#include <algorithm>
#include <limits>
#include <unordered_set>

#include "core/map/traversability_map.hpp"

namespace storey::core::map {

namespace {
// The 8 neighbouring columns, then the 8 one stride away (two voxels, straight or diagonal).
constexpr int kNeighbours = 16;
constexpr int kDx[kNeighbours] = {1, -1, 0, 0, 1, 1, -1, -1, 2, -2, 0, 0, 2, 2, -2, -2};
constexpr int kDy[kNeighbours] = {0, 0, 1, -1, 1, -1, 1, -1, 0, 0, 2, -2, 2, -2, 2, -2};

// A stride up or down a step (heights differ by at least kMinStrideRiseM) crosses the column
// between a and b if nothing in it stands more than a step above the higher end (a wall, a
// post): a Go2's stride clears the one-voxel strip of a stair tread the LiDAR did not see (seen
// edge-on from below, rays grazing over it keep its voxels free). Level ground with a hole in
// the map stays unbridged: that is what tentative edges are for.
constexpr float kMinStrideRiseM = 0.08f;
template <typename Occupied, typename Height>
bool stride_clear(const VoxelKey& a, const VoxelKey& b, float ha, float hb, int below, int above,
                  float step, Occupied&& occupied, Height&& height) {
  if (std::abs(b.x - a.x) < 2 && std::abs(b.y - a.y) < 2) return true;
  if (std::abs(hb - ha) < kMinStrideRiseM) return false;
  const float h_top = std::max(ha, hb);
  const int32_t mx = a.x + (b.x - a.x) / 2, my = a.y + (b.y - a.y) / 2;
  for (int32_t z = std::min(a.z, b.z) - below; z <= std::max(a.z, b.z) + above; ++z) {
    const VoxelKey m{mx, my, z};
    if (occupied(m) && height(m) > h_top + step) return false;
  }
  return true;
}
}  // namespace

bool TraversabilityMap::connected(const VoxelKey& a, const VoxelKey& b) {
  const Cell* ca = rcell(a);
  if (!ca || ca->state != TravState::kTraversable) return false;
  const float ha = surface_height(a, rstats(a));
  const Cell* cb = rcell(b);
  if (!cb || cb->state != TravState::kTraversable) return false;
  const float hb = surface_height(b, rstats(b));
  if (std::abs(hb - ha) > robot_.step_height_m + step_slack(rstats(a), rstats(b))) return false;
  return stride_clear(
      a, b, ha, hb, dz_step_, h_clear_, float(robot_.step_height_m),
      [&](const VoxelKey& m) { return occupied(rcell(m)); },
      [&](const VoxelKey& m) { return surface_height(m, rstats(m)); });
}

bool TraversabilityMap::has_parent(const VoxelKey& k, uint32_t dist) {
  for (int i = 0; i < kNeighbours; ++i)
    for (int dz = -dz_step_; dz <= dz_step_; ++dz) {
      const VoxelKey w{k.x + kDx[i], k.y + kDy[i], k.z + dz};
      const Cell* cw = rcell(w);
      if (!cw || !(cw->flags & Cell::kReachable)) continue;
      if (rstats(w)->reach_dist < dist && connected(k, w)) return true;
    }
  return false;
}

void TraversabilityMap::set_reachable(const VoxelKey& k, uint32_t dist) {
  VoxelBlock* b = wblock(k, false);
  Cell& c = b->cells[cell_index(k)];
  if (!(c.flags & Cell::kReachable)) ++reach_count_;
  c.flags |= Cell::kReachable;
  b->stats[c.stats].reach_dist = dist;
}

void TraversabilityMap::clear_reachable(const VoxelKey& k) {
  Cell* c = wcell(k);
  if (c && (c->flags & Cell::kReachable)) {
    c->flags &= ~Cell::kReachable;
    --reach_count_;
  }
}

std::optional<VoxelKey> TraversabilityMap::find_seed(const Eigen::Vector3f& foot) {
  const double s = opt_.voxel_size_m;
  const int r = int(std::ceil(opt_.seed_search_radius_m / s));
  const int32_t cx = int32_t(std::floor(foot.x() / s)), cy = int32_t(std::floor(foot.y() / s));
  const int32_t cz = int32_t(std::floor(foot.z() / s));
  std::optional<VoxelKey> best;
  double best_d = std::numeric_limits<double>::infinity();
  bool best_reach = false;
  for (int dx = -r; dx <= r; ++dx)
    for (int dy = -r; dy <= r; ++dy) {
      const double d2 = double(dx * dx + dy * dy);
      if (d2 > double(r * r)) continue;
      for (int dz = -dz_step_ - 1; dz <= dz_step_ + 1; ++dz) {
        const VoxelKey k{cx + dx, cy + dy, cz + dz};
        const Cell* c = rcell(k);
        if (!c || c->state != TravState::kTraversable) continue;
        const double dh = surface_height(k, rstats(k)) - foot.z();
        if (std::abs(dh) > robot_.step_height_m) continue;
        // Prefer members of C_reach (the robot stands on the component it came from), and with
        // seed_under_feet the support under the body at the feet's level as well: after a blind
        // climb the robot stands on a landing C_reach never reached, and the flight's treads
        // within the search radius are a step lower.
        const bool under = opt_.seed_under_feet && d2 * s * s <= 0.35 * 0.35 &&
                           std::abs(dh) <= 0.5 * robot_.step_height_m;
        const bool reach = (c->flags & Cell::kReachable) || under;
        const double d = d2 * s * s + dh * dh;
        if ((reach && !best_reach) || (reach == best_reach && d < best_d)) {
          best = k;
          best_d = d;
          best_reach = reach;
        }
      }
    }
  return best;
}

void TraversabilityMap::grow_bfs(ReachUpdateStats& st) {
  for (size_t q = 0; q < grow_queue_.size(); ++q) {
    const VoxelKey u = grow_queue_[q];
    const uint32_t du = rstats(u)->reach_dist;
    for (int i = 0; i < kNeighbours; ++i)
      for (int dz = -dz_step_; dz <= dz_step_; ++dz) {
        const VoxelKey w{u.x + kDx[i], u.y + kDy[i], u.z + dz};
        const Cell* cw = rcell(w);
        if (!cw || cw->state != TravState::kTraversable || (cw->flags & Cell::kReachable)) continue;
        if (!connected(u, w)) continue;
        set_reachable(w, du + 1);
        grow_queue_.push_back(w);
        ++st.grown;
      }
  }
  grow_queue_.clear();
}

void TraversabilityMap::regrow_from(const VoxelKey& seed, ReachUpdateStats& st) {
  st.full_regrow = true;
  orphans_.clear();
  MapView(store_, opt_, robot_)
      .for_each_occupied([&](const VoxelKey& k, const Cell& c, const VoxelStats*) {
        if (c.flags & Cell::kReachable) orphans_.push_back(k);
      });
  for (const VoxelKey& k : orphans_) clear_reachable(k);
  st.orphaned += uint32_t(orphans_.size());
  orphans_.clear();
  roots_.assign(1, seed);
  set_reachable(seed, 0);
  ++st.grown;
  grow_queue_.clear();
  grow_queue_.push_back(seed);
  grow_bfs(st);
}

ReachUpdateStats TraversabilityMap::update_reachable(const Eigen::Vector3f& foot) {
  ReachUpdateStats st;
  const std::optional<VoxelKey> seed = find_seed(foot);
  st.has_seed = seed.has_value();
  orphan_queue_.clear();
  orphans_.clear();
  // Roots that are no longer traversable leave the forest; they are orphaned below.
  for (size_t i = 0; i < roots_.size();) {
    const Cell* c = rcell(roots_[i]);
    if (c && c->state == TravState::kTraversable) {
      ++i;
      continue;
    }
    if (c && (c->flags & Cell::kReachable)) {
      clear_reachable(roots_[i]);
      orphans_.push_back(roots_[i]);
      ++st.orphaned;
    }
    orphan_queue_.push_back({roots_[i], 0});
    roots_.erase(roots_.begin() + long(i));
  }
  if (roots_.empty()) {
    // No forest left: rebuild from the robot (or empty the set).
    if (seed) {
      regrow_from(*seed, st);
    } else {
      orphans_.clear();
      MapView(store_, opt_, robot_)
          .for_each_occupied([&](const VoxelKey& k, const Cell& c, const VoxelStats*) {
            if (c.flags & Cell::kReachable) orphans_.push_back(k);
          });
      for (const VoxelKey& k : orphans_) clear_reachable(k);
      st.orphaned += uint32_t(orphans_.size());
      orphans_.clear();
    }
    reach_changed_.clear();
    return st;
  }

  // Decremental pass. Sources: members that changed. A member that is no longer traversable
  // or lost every parent edge is orphaned; every source (orphaned or not, since its height may
  // have changed) has its larger-count neighbours re-checked.
  for (const ReachChange& rc : reach_changed_) {
    if (!rc.was_reachable) continue;
    const Cell* c = rcell(rc.key);
    if (!c || !(c->flags & Cell::kReachable)) {  // turned free, or a duplicate entry
      orphan_queue_.push_back({rc.key, rc.old_dist});
      continue;
    }
    if (is_root(rc.key)) {
      orphan_queue_.push_back({rc.key, 0});
      continue;
    }
    const uint32_t d = rstats(rc.key) ? rstats(rc.key)->reach_dist : rc.old_dist;
    if (c->state != TravState::kTraversable || !has_parent(rc.key, d)) {
      clear_reachable(rc.key);
      orphans_.push_back(rc.key);
      ++st.orphaned;
    }
    orphan_queue_.push_back({rc.key, d});
  }
  for (size_t q = 0; q < orphan_queue_.size(); ++q) {
    const auto [u, du] = orphan_queue_[q];
    for (int i = 0; i < kNeighbours; ++i)
      for (int dz = -dz_step_; dz <= dz_step_; ++dz) {
        const VoxelKey w{u.x + kDx[i], u.y + kDy[i], u.z + dz};
        const Cell* cw = rcell(w);
        if (!cw || !(cw->flags & Cell::kReachable) || is_root(w)) continue;
        const uint32_t dw = rstats(w)->reach_dist;
        if (dw <= du || has_parent(w, dw)) continue;
        clear_reachable(w);
        orphans_.push_back(w);
        orphan_queue_.push_back({w, dw});
        ++st.orphaned;
      }
  }

  // Incremental growth: orphans and changed voxels that touch C_reach rejoin it, then BFS.
  grow_queue_.clear();
  auto attach = [&](const VoxelKey& k) {
    const Cell* c = rcell(k);
    if (!c || c->state != TravState::kTraversable || (c->flags & Cell::kReachable)) return;
    uint32_t best = std::numeric_limits<uint32_t>::max();
    for (int i = 0; i < kNeighbours; ++i)
      for (int dz = -dz_step_; dz <= dz_step_; ++dz) {
        const VoxelKey w{k.x + kDx[i], k.y + kDy[i], k.z + dz};
        const Cell* cw = rcell(w);
        if (!cw || !(cw->flags & Cell::kReachable) || !connected(k, w)) continue;
        best = std::min(best, rstats(w)->reach_dist);
      }
    if (best == std::numeric_limits<uint32_t>::max()) return;
    set_reachable(k, best + 1);
    grow_queue_.push_back(k);
    ++st.grown;
  };
  for (const VoxelKey& k : orphans_) attach(k);
  for (const ReachChange& rc : reach_changed_) attach(rc.key);
  grow_bfs(st);
  reach_changed_.clear();
  orphans_.clear();

  // The robot stands on ground C_reach does not contain: that ground is reachable too.
  if (seed && !(rcell(*seed)->flags & Cell::kReachable)) {
    if (roots_.size() >= kMaxRoots) {
      regrow_from(*seed, st);  // bounded forest: start over from the robot
    } else {
      st.new_root = true;
      roots_.push_back(*seed);
      set_reachable(*seed, 0);
      ++st.grown;
      grow_queue_.push_back(*seed);
      grow_bfs(st);
    }
  }
  return st;
}

std::vector<VoxelKey> TraversabilityMap::grow_from_scratch(
    const std::vector<VoxelKey>& seeds) const {
  BlockReader r(store_);
  auto trav = [&](const VoxelKey& k) {
    const Cell* c = r.cell(k);
    return c && c->state == TravState::kTraversable;
  };
  auto height = [&](const VoxelKey& k) { return surface_height(k, r.stats(k)); };
  struct Hash {
    size_t operator()(const VoxelKey& k) const {
      return size_t(k.x) * 73856093u ^ size_t(k.y) * 19349663u ^ size_t(k.z) * 83492791u;
    }
  };
  std::vector<VoxelKey> out;
  std::unordered_set<VoxelKey, Hash> seen;
  for (const VoxelKey& s : seeds)
    if (trav(s) && seen.insert(s).second) out.push_back(s);
  for (size_t q = 0; q < out.size(); ++q) {
    const VoxelKey u = out[q];
    const float hu = height(u);
    for (int i = 0; i < kNeighbours; ++i)
      for (int dz = -dz_step_; dz <= dz_step_; ++dz) {
        const VoxelKey w{u.x + kDx[i], u.y + kDy[i], u.z + dz};
        if (seen.count(w) || !trav(w) ||
            std::abs(height(w) - hu) > robot_.step_height_m + step_slack(r.stats(u), r.stats(w)))
          continue;
        auto occ = [&](const VoxelKey& m) {
          const Cell* c = r.cell(m);
          return c && (c->flags & Cell::kObserved) && c->log_odds > occ_q_;
        };
        if (!stride_clear(u, w, hu, height(w), dz_step_, h_clear_, float(robot_.step_height_m), occ,
                          height))
          continue;
        seen.insert(w);
        out.push_back(w);
      }
  }
  return out;
}

}  // namespace storey::core::map
