#pragma once
// Read-only queries on the traversability map (paper Sec. III-A), used by the reachable graph,
// frontiers, viewpoints, A* and the FCL look-ahead. A MapView is references plus a block cache:
// over a MapSnapshot it is valid as long as the snapshot lives; over the live map it is valid
// only on the owner thread and only until the next mutating call on the map. The cache makes a
// view single-threaded: make one view per thread (construction is free).
#include <cmath>
#include <cstdint>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "core/map/block_store.hpp"
#include "core/map/map_options.hpp"
#include "core/map/voxel_block.hpp"
#include "core/robot_model.hpp"

namespace storey::core::map {

// Caches the last 16 blocks looked up (direct-mapped by block coordinate, so neighbourhood
// scans that straddle block borders stay off the hash table). Invalidation: holds raw pointers
// into `store`; it must not outlive a write to `store` (the owner's copy-on-write may swap the
// block behind a key). Every MapView query builds its own BlockReader, so views never hold
// stale pointers; the owner calls invalidate() whenever a write cloned a block.
class BlockReader {
 public:
  explicit BlockReader(const BlockStore& store) : store_(&store) {}
  const VoxelBlock* block(const VoxelKey& k) {
    const uint64_t bk = block_key_of(k);
    const int slot = ((k.x >> kBlockBits) & 3) | (((k.y >> kBlockBits) & 1) << 2) |
                     (((k.z >> kBlockBits) & 1) << 3);
    Entry& e = cache_[slot];
    if (!e.valid || e.key != bk) {
      e.key = bk;
      e.block = store_->find(bk);
      e.valid = true;
    }
    return e.block;
  }
  const Cell* cell(const VoxelKey& k) {
    const VoxelBlock* b = block(k);
    return b ? &b->cells[cell_index(k)] : nullptr;
  }
  // Statistics of k, or nullptr if it has none.
  const VoxelStats* stats(const VoxelKey& k) {
    const VoxelBlock* b = block(k);
    if (!b) return nullptr;
    const Cell& c = b->cells[cell_index(k)];
    return c.stats == Cell::kNoStats ? nullptr : &b->stats[c.stats];
  }
  void invalidate() {
    for (Entry& e : cache_) e.valid = false;
  }

 private:
  struct Entry {
    uint64_t key = 0;
    const VoxelBlock* block = nullptr;
    bool valid = false;
  };
  const BlockStore* store_;
  Entry cache_[16];
};

// A support voxel found near a query point.
struct SurfacePoint {
  VoxelKey key;
  float height_m = 0;  // surface height: mean z of the voxel's points [m]
  TravState state = TravState::kNone;
  bool reachable = false;  // member of C_reach
};

class MapView {
 public:
  MapView(const BlockStore& store, const MapOptions& options, const RobotModel& robot)
      : store_(&store), opt_(&options), robot_(&robot), cache_(store) {}

  double voxel_size_m() const { return opt_->voxel_size_m; }
  VoxelKey key_of(const Eigen::Vector3f& p_m) const;
  Eigen::Vector3f centre_of(const VoxelKey& k) const;

  // Occupancy from log-odds: unknown (never observed), free, occupied.
  Occupancy occupancy(const VoxelKey& k) const;
  Occupancy occupancy(const Eigen::Vector3f& p_m) const { return occupancy(key_of(p_m)); }
  bool is_occupied(const VoxelKey& k) const { return occupancy(k) == Occupancy::kOccupied; }
  // Support voxel: occupied, and the voxel directly above is not occupied.
  bool is_support(const VoxelKey& k) const;
  TravState state(const VoxelKey& k) const;  // tau(v), Eq. 3 (kNone if not occupied)
  bool is_traversable(const VoxelKey& k) const { return state(k) == TravState::kTraversable; }
  bool is_reachable(const VoxelKey& k) const;     // v in C_reach
  uint32_t point_count(const VoxelKey& k) const;  // N(v)
  float cost(const VoxelKey& k) const;            // c(v), Eq. 2 (0 if never evaluated)
  bool is_step_edge(const VoxelKey& k) const;     // occupied, VoxelStats::kStepEdge
  // A step edge's riser (VoxelStats::kStepEdge): the horizontal unit normal of its points
  // (sign arbitrary); nullopt if k is not an occupied step edge.
  std::optional<Eigen::Vector2f> riser_normal(const VoxelKey& k) const;
  // Surface height of an occupied voxel: centre z + mean of its points [m].
  std::optional<float> surface_height_m(const VoxelKey& k) const;

  // Support surface near (x, y, z): the support voxel in the column under (x, y) whose surface
  // height is closest to z within [z - window_m, z + window_m]; nullopt if none (I(x, z) = 0 in
  // the paper's missing-surface ratio, Eq. 5).
  std::optional<SurfacePoint> support_surface_near(const Eigen::Vector3f& p_m,
                                                   double window_m) const;

  // Visibility: the first occupied voxel on the segment from -> to (excluding the voxel of
  // `from`), nullopt if none.
  std::optional<VoxelKey> first_occupied(const Eigen::Vector3f& from_m,
                                         const Eigen::Vector3f& to_m) const;
  // True if no voxel on the segment is occupied (and, unless unknown_is_free, none is unknown).
  bool is_segment_free(const Eigen::Vector3f& from_m, const Eigen::Vector3f& to_m,
                       bool unknown_is_free) const;
  // Probe for frontiers: walks from -> to and reports the first non-free voxel's occupancy
  // (kFree if the whole segment is known free). `hit` receives that voxel if given.
  Occupancy probe(const Eigen::Vector3f& from_m, const Eigen::Vector3f& to_m,
                  VoxelKey* hit = nullptr) const;
  // Free space above a surface voxel: the voxels from k.z+1 up to height_m above the surface
  // are not occupied (and known, unless unknown_is_free). For A* through the free voxels above
  // the traversable surface (paper Sec. IV-D, Stage 3).
  bool is_free_above(const VoxelKey& k, double height_m, bool unknown_is_free) const;
  // Centres of the occupied voxels in the axis-aligned box centre +- half_extent (for FCL
  // checks of the body against the map). Appends to `out`; returns how many were appended.
  size_t occupied_in_box(const Eigen::Vector3f& centre_m, const Eigen::Vector3f& half_extent_m,
                         std::vector<Eigen::Vector3f>& out) const;

  // The part of an occupied voxel its points fill, per axis mean +- (2 sd + 1 cm) clipped to the
  // voxel, where the voxel holds at least n_min points (else the whole voxel on every axis). A
  // riser seen in a voxel that reaches 9 cm in front of it, or a wall face on a voxel boundary,
  // is then where the points put it (FCL checks of the body: paper IV-D, Stage 3).
  struct VoxelExtent {
    Eigen::Vector3f centre_m = Eigen::Vector3f::Zero();
    Eigen::Vector3f half_m = Eigen::Vector3f::Zero();
    float surface_z_m = 0;  // centre z + mean z of the points (as surface_height_m)
  };
  size_t occupied_extents_in_box(const Eigen::Vector3f& centre_m,
                                 const Eigen::Vector3f& half_extent_m,
                                 std::vector<VoxelExtent>& out) const;

  // Iterate occupied voxels: f(key, cell, stats*).
  template <class F>
  void for_each_occupied(F&& f) const {
    const int16_t occ = int16_t(std::lround(opt_->log_odds_occupied * kLogOddsScale));
    store_->for_each([&](const VoxelBlock& b) {
      for (int i = 0; i < kBlockCells; ++i) {
        const Cell& c = b.cells[i];
        if (!(c.flags & Cell::kObserved) || c.log_odds <= occ) continue;
        const VoxelKey k{(b.bx << kBlockBits) | (i >> (2 * kBlockBits)),
                         (b.by << kBlockBits) | ((i >> kBlockBits) & kBlockMask),
                         (b.bz << kBlockBits) | (i & kBlockMask)};
        f(k, c, c.stats == Cell::kNoStats ? nullptr : &b.stats[c.stats]);
      }
    });
  }

  const MapOptions& options() const { return *opt_; }
  const RobotModel& robot() const { return *robot_; }
  const BlockStore& store() const { return *store_; }

 private:
  const BlockStore* store_;
  const MapOptions* opt_;
  const RobotModel* robot_;
  // Consecutive queries mostly touch the same blocks (A* expansions, probes): keep them.
  // Invalidation: dropped whenever the store cloned (copy-on-write) or created a block since
  // the last query, so even a live-map view kept past a mutating call never dereferences a
  // replaced block (its answers are then merely as of that call).
  BlockReader& reader() const {
    const uint64_t gen = store_->cow_copies() + store_->block_count();
    if (gen != cache_gen_) {
      cache_.invalidate();
      cache_gen_ = gen;
    }
    return cache_;
  }
  mutable BlockReader cache_;
  mutable uint64_t cache_gen_ = ~uint64_t{0};
};

}  // namespace storey::core::map
