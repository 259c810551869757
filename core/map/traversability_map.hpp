#pragma once
// Traversability-aware volumetric map and reachable set C_reach (paper Sec. III-A).
//
// Owned by one thread (the firmware's map task). Per scan: insert_scan() (ray casting, voxel
// statistics), update_traversability() (Eq. 1-3 on the dirty set), update_reachable() (C_reach),
// then snapshot() publishes an immutable copy-on-write view for other threads.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include <Eigen/Core>

#include "core/map/block_store.hpp"
#include "core/map/map_options.hpp"
#include "core/map/map_view.hpp"
#include "core/map/voxel_block.hpp"
#include "core/robot_model.hpp"

namespace storey::core::map {

// One LiDAR sweep, already deskewed and expressed in the world frame.
struct Scan {
  Eigen::Vector3f origin_m = Eigen::Vector3f::Zero();  // sensor origin [m]
  std::span<const Eigen::Vector3f> points_m;           // returns [m]
  std::span<const double> stamps_s;                    // optional per-point times [s] (unused)
};

struct InsertStats {
  uint32_t points = 0;             // points offered
  uint32_t hits = 0;               // points inserted as endpoints
  uint32_t dropped_invalid = 0;    // NaN/inf or beyond world_limit_m (counted, never inserted)
  uint32_t dropped_min_range = 0;  // closer than min_range_m
  uint32_t truncated = 0;          // beyond max_range_m: free space only
  uint32_t rays_cast = 0;          // rays walked after de-duplication by endpoint voxel
  uint64_t voxels_walked = 0;      // DDA steps
  uint32_t changed = 0;            // voxels that flipped occupancy or whose N(v) grew enough
  bool origin_invalid = false;     // whole scan rejected: non-finite / out-of-world origin
};

struct TravUpdateStats {
  uint32_t evaluated = 0;      // voxels whose tau(v) was recomputed
  uint32_t state_changes = 0;  // of which changed state
};

struct ReachUpdateStats {
  bool has_seed = false;     // a traversable support voxel was found under the robot
  bool full_regrow = false;  // the set was regrown from the seed (every root lost)
  bool new_root = false;     // the seed was outside C_reach and became a root
  uint32_t orphaned = 0;     // voxels removed by the decremental pass
  uint32_t grown = 0;        // voxels added
};

class MapSnapshot;

class TraversabilityMap {
 public:
  explicit TraversabilityMap(const MapOptions& options = {}, const RobotModel& robot = {});

  // Ray-casts one scan: free space along each ray, endpoint occupied (log-odds clamped), each
  // voxel updated at most once per scan for a miss and once for a hit (hit wins). Rays are
  // de-duplicated by endpoint voxel: the first point of an endpoint voxel casts its ray, later
  // points in that voxel only add statistics. Records which voxels changed for the next
  // update_traversability().
  InsertStats insert_scan(const Eigen::Vector3f& origin_m,
                          std::span<const Eigen::Vector3f> points_m);
  InsertStats insert_scan(const Scan& scan) { return insert_scan(scan.origin_m, scan.points_m); }

  // Recomputes tau(v) (Eq. 1-3) for the voxels touched since the last call and the
  // neighbourhoods that depend on them.
  TravUpdateStats update_traversability();

  // Maintains C_reach: seed = nearest traversable support voxel under the robot's feet
  // (robot_foot_m: a point on the ground between the feet [m]). The set is the union of the
  // components of the roots: the first seed, plus every later seed that was not already in the
  // set (the robot crossed ground too under-observed to connect yet; where it walked stays
  // reachable). A root that turns untraversable is dropped; with no root left, the set is
  // regrown from the current seed.
  ReachUpdateStats update_reachable(const Eigen::Vector3f& robot_foot_m);

  // Immutable, shareable view of the current map (copy-on-write of blocks).
  std::shared_ptr<const MapSnapshot> snapshot();

  // Queries on the live map (owner thread only, valid until the next mutating call).
  MapView view() const { return MapView(store_, opt_, robot_); }

  // C_reach recomputed from scratch from `seeds` (testing / validation): keys in BFS order.
  std::vector<VoxelKey> grow_from_scratch(const std::vector<VoxelKey>& seeds) const;
  const std::vector<VoxelKey>& reach_roots() const { return roots_; }

  uint64_t occupied_voxels() const { return occupied_count_; }
  uint64_t traversable_voxels() const { return trav_count_; }
  uint64_t reachable_voxels() const { return reach_count_; }
  double voxel_volume_m3() const {
    return opt_.voxel_size_m * opt_.voxel_size_m * opt_.voxel_size_m;
  }
  double occupied_volume_m3() const { return double(occupied_count_) * voxel_volume_m3(); }
  double traversable_volume_m3() const { return double(trav_count_) * voxel_volume_m3(); }
  double reachable_volume_m3() const { return double(reach_count_) * voxel_volume_m3(); }
  size_t mem_usage() const;  // bytes: blocks, hash table, scratch lists
  uint64_t version() const { return version_; }
  const MapOptions& options() const { return opt_; }
  const RobotModel& robot() const { return robot_; }

 private:
  struct ReachChange {
    VoxelKey key;
    uint32_t old_dist;
    bool was_reachable;
  };
  // Owner-side accessors. Write cache: invalidated at the start of every scan (so the per-scan
  // de-dup bits of a cached block are reset) and in snapshot() (blocks become shared and must be
  // cloned before the next write). Read cache: invalidated whenever a write cloned a block.
  VoxelBlock* wblock(const VoxelKey& k, bool create);
  Cell* wcell(const VoxelKey& k) {
    VoxelBlock* b = wblock(k, false);
    return b ? &b->cells[cell_index(k)] : nullptr;
  }
  const Cell* rcell(const VoxelKey& k) {
    if (store_.cow_copies() != reader_cow_) {
      reader_.invalidate();
      reader_cow_ = store_.cow_copies();
    }
    return reader_.cell(k);
  }
  const VoxelStats* rstats(const VoxelKey& k) {
    const Cell* c = rcell(k);
    return c && c->stats != Cell::kNoStats ? reader_.stats(k) : nullptr;
  }
  bool occupied(const Cell* c) const {
    return c && (c->flags & Cell::kObserved) && c->log_odds > occ_q_;
  }
  float surface_height(const VoxelKey& k, const VoxelStats* s) const {
    return float((k.z + 0.5) * opt_.voxel_size_m) + surface_offset(s, float(opt_.voxel_size_m));
  }
  // Where the feet stand on v: the top of its points, mean + one standard deviation in z
  // (within the voxel). A stair's nosing voxel also holds riser points below the tread that
  // pull the mean down, by about as much as the 1 cm between a 0.167 m rise and the 0.18 m step.
  float standing_height(const VoxelKey& k, const VoxelStats* s) const {
    const float h = surface_height(k, s);
    if (!s || !s->count || (s->shape & VoxelStats::kStepEdge)) return h;  // already the top
    const float sd = std::sqrt(std::max(0.0f, s->m2[5] / float(s->count)));
    return std::min(h + sd, float((k.z + 1) * opt_.voxel_size_m));
  }
  void mark_changed(const VoxelKey& k, Cell& c);
  TravState evaluate(const VoxelKey& k, VoxelStats* s);        // Eq. 1-3 for one voxel
  bool step_edge(const VoxelKey& k, const VoxelStats& s);      // VoxelStats::kStepEdge test
  bool surface_spill(const VoxelKey& k, const VoxelStats& s);  // under N_min, still a floor
  bool connected(const VoxelKey& a, const VoxelKey& b);        // C_reach adjacency
  bool has_parent(const VoxelKey& k, uint32_t dist);
  void set_reachable(const VoxelKey& k, uint32_t dist);
  void clear_reachable(const VoxelKey& k);
  void regrow_from(const VoxelKey& seed, ReachUpdateStats& st);
  void grow_bfs(ReachUpdateStats& st);
  std::optional<VoxelKey> find_seed(const Eigen::Vector3f& foot);

  MapOptions opt_;
  RobotModel robot_;
  BlockStore store_;
  BlockReader reader_{store_};
  uint64_t reader_cow_ = 0;
  uint64_t wkey_ = 0;
  VoxelBlock* wblock_ = nullptr;
  uint32_t scan_id_ = 0;
  uint64_t version_ = 0;

  // Quantised parameters (voxel units / fixed-point log-odds).
  int16_t hit_q_, miss_q_, min_q_, max_q_, occ_q_;
  int r_agg_, r_col_, dz_step_, h_clear_, dz_agg_;

  // Scratch, reused across scans (no allocation in steady state once grown).
  std::vector<uint32_t> ray_points_;
  std::vector<VoxelKey> changed_;
  std::vector<VoxelKey> dirty_;
  std::vector<ReachChange> reach_changed_;
  std::vector<std::pair<VoxelKey, uint32_t>> orphan_queue_;
  std::vector<VoxelKey> orphans_;
  std::vector<VoxelKey> grow_queue_;

  bool is_root(const VoxelKey& k) const {
    return std::find(roots_.begin(), roots_.end(), k) != roots_.end();
  }
  static constexpr size_t kMaxRoots = 64;
  std::vector<VoxelKey> roots_;  // dist 0 members of the BFS forest
  uint64_t occupied_count_ = 0, trav_count_ = 0, reach_count_ = 0;
};

// Immutable copy of the map for readers on other threads. Shares unchanged blocks with the
// owner; the owner clones a block before its next write (copy-on-write), so a snapshot never
// changes. Releasing the last reference frees the blocks only the snapshot still held.
class MapSnapshot {
 public:
  MapSnapshot(BlockStore store, const MapOptions& o, const RobotModel& r, uint64_t version,
              uint64_t occupied, uint64_t traversable, uint64_t reachable)
      : store_(std::move(store)),
        opt_(o),
        robot_(r),
        version_(version),
        occupied_(occupied),
        traversable_(traversable),
        reachable_(reachable) {}
  MapView view() const { return MapView(store_, opt_, robot_); }
  uint64_t version() const { return version_; }
  uint64_t occupied_voxels() const { return occupied_; }
  uint64_t traversable_voxels() const { return traversable_; }
  uint64_t reachable_voxels() const { return reachable_; }
  double voxel_volume_m3() const {
    return opt_.voxel_size_m * opt_.voxel_size_m * opt_.voxel_size_m;
  }
  double occupied_volume_m3() const { return double(occupied_) * voxel_volume_m3(); }
  double traversable_volume_m3() const { return double(traversable_) * voxel_volume_m3(); }

 private:
  BlockStore store_;
  MapOptions opt_;
  RobotModel robot_;
  uint64_t version_, occupied_, traversable_, reachable_;
};

}  // namespace storey::core::map
