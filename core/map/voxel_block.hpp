#pragma once
// Packed voxel cells and 8^3 voxel blocks of the sparse map (Bonxai-style, paper Sec. III-A).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

namespace storey::core::map {

// Integer voxel coordinate: voxel (x,y,z) covers [x*s, (x+1)*s) on each axis, s = voxel size.
struct VoxelKey {
  int32_t x = 0, y = 0, z = 0;
  friend bool operator==(const VoxelKey&, const VoxelKey&) = default;
};

inline constexpr int kBlockBits = 3;  // 8 voxels per block edge
inline constexpr int kBlockDim = 1 << kBlockBits;
inline constexpr int kBlockMask = kBlockDim - 1;
inline constexpr int kBlockCells = kBlockDim * kBlockDim * kBlockDim;

// Block coordinates packed into 64 bits, 21 bits per axis (two's complement): +-2^20 blocks.
inline uint64_t pack_block_key(int32_t bx, int32_t by, int32_t bz) {
  constexpr uint64_t m = (uint64_t{1} << 21) - 1;
  return ((uint64_t(uint32_t(bx)) & m) << 42) | ((uint64_t(uint32_t(by)) & m) << 21) |
         (uint64_t(uint32_t(bz)) & m);
}
inline uint64_t block_key_of(const VoxelKey& k) {
  return pack_block_key(k.x >> kBlockBits, k.y >> kBlockBits, k.z >> kBlockBits);
}
// Cell index inside a block; z innermost so a column walk stays in cache.
inline int cell_index(const VoxelKey& k) {
  return ((k.x & kBlockMask) << (2 * kBlockBits)) | ((k.y & kBlockMask) << kBlockBits) |
         (k.z & kBlockMask);
}

// Traversability state tau(v), paper Eq. 3. kNone: not an occupied voxel (free/unknown).
enum class TravState : uint8_t { kNone = 0, kUnobserved = 1, kTraversable = 2, kUntraversable = 3 };

// Occupancy of a point for frontier probes.
enum class Occupancy : uint8_t { kUnknown = 0, kFree = 1, kOccupied = 2 };

// One voxel, 6 bytes. Log-odds in fixed point (kLogOddsScale per unit) so cells stay small.
struct Cell {
  static constexpr uint16_t kNoStats = 0xFFFF;
  static constexpr uint8_t kObserved = 1;   // touched by at least one ray
  static constexpr uint8_t kReachable = 2;  // member of C_reach
  static constexpr uint8_t kQueued = 4;     // in the traversability dirty set (owner scratch)
  static constexpr uint8_t kChanged = 8;    // in this scan's changed list (owner scratch)
  int16_t log_odds = 0;
  uint16_t stats = kNoStats;  // index into VoxelBlock::stats, or kNoStats
  uint8_t flags = 0;
  TravState state = TravState::kNone;
};
static_assert(sizeof(Cell) == 6, "Cell must stay packed");
inline constexpr float kLogOddsScale = 1000.0f;

// Point statistics of an occupied voxel, accumulated online (Welford / West). The mean and the
// scatter matrix are relative to the voxel centre so float keeps ~1e-7 m precision anywhere.
struct VoxelStats {
  uint32_t count = 0;         // N(v)
  uint32_t count_eval = 0;    // N(v) when tau(v) was last evaluated (re-evaluate on doubling)
  float mean[3] = {0, 0, 0};  // relative to the voxel centre [m]
  float m2[6] = {0, 0, 0, 0, 0, 0};  // scatter sum (xx, xy, xz, yy, yz, zz) [m^2]
  float cost = 0;                    // c(v), Eq. 2 (NaN-free; 0 until evaluated)
  float normal_z = 1;                // |n_v . e_z| of the aggregated normal
  uint32_t reach_dist = 0;           // hop count from the C_reach root (decremental BFS invariant)
  uint8_t reasons = 0;  // why tau(v) is not S_trav: kReason* bits (diagnostics, export)
  uint8_t shape = 0;    // kStepEdge: set before tau(v) from v's points, the voxel above and
                        // the neighbours' means (TraversabilityMap::step_edge)
  // The lowest rise of the rays that hit v, (z_point - z_sensor) / horizontal distance, in
  // hundredths (clamped to +-127): a surface is seen from above only by a ray rising less than
  // its own slope (MapOptions::floor_seen_from_above). In the padding: no larger.
  int8_t min_rise = 127;

  static constexpr uint8_t kReasonNotTop = 1;  // voxel above is occupied, or v was seen only from
                                               // below (floor_seen_from_above): not a surface
  static constexpr uint8_t kReasonDegenerate = 2;  // neighbourhood points are collinear
  static constexpr uint8_t kReasonCost = 4;        // c(v) > tau_c
  static constexpr uint8_t kReasonCollision = 8;   // R_col(v)
  static constexpr uint8_t kReasonFall = 16;       // R_fall(v)

  // A step edge: v's own points are a steep sheet reaching v's upper half under observed free
  // space: the riser of a step whose tread lies at the sheet's top (a stair nosing, a kerb). A
  // tread on a voxel boundary leaves only the riser's top in the column behind the nosing.
  static constexpr uint8_t kStepEdge = 1;

  void add(float px, float py, float pz) {
    ++count;
    const float inv = 1.0f / float(count);
    const float d0 = px - mean[0], d1 = py - mean[1], d2 = pz - mean[2];
    mean[0] += d0 * inv;
    mean[1] += d1 * inv;
    mean[2] += d2 * inv;
    const float e0 = px - mean[0], e1 = py - mean[1], e2 = pz - mean[2];
    m2[0] += d0 * e0;
    m2[1] += d0 * e1;
    m2[2] += d0 * e2;
    m2[3] += d1 * e1;
    m2[4] += d1 * e2;
    m2[5] += d2 * e2;
  }
  void reset() { *this = VoxelStats{}; }
};

// Height of v's surface relative to its centre: the points' mean, or for a step edge the top
// of its riser (mean + sqrt(3) sd: the upper end of points spread evenly over the riser's
// height), within the voxel.
inline float sheet_top_offset(const VoxelStats& s) {
  const float sd = std::sqrt(std::max(0.0f, s.m2[5] / float(std::max(1u, s.count))));
  return s.mean[2] + 1.7320508f * sd;
}
inline float surface_offset(const VoxelStats* s, float voxel_size) {
  if (!s || !s->count) return 0.0f;
  if (!(s->shape & VoxelStats::kStepEdge)) return s->mean[2];
  return std::min(sheet_top_offset(*s), 0.5f * voxel_size);
}

// A step edge's height is an estimate from moments: with a strip of tread on top of its riser
// the points are not spread evenly and mean + sqrt(3) sd lands up to ~2 cm above the tread.
// Step-height comparisons involving a step edge allow this much more.
inline constexpr float kStepEdgeSlackM = 0.025f;
inline float step_slack(const VoxelStats* a, const VoxelStats* b = nullptr) {
  const bool edge =
      (a && (a->shape & VoxelStats::kStepEdge)) || (b && (b->shape & VoxelStats::kStepEdge));
  return edge ? kStepEdgeSlackM : 0.0f;
}

// 8^3 cells plus the statistics of the occupied ones. Copied as a whole on copy-on-write.
struct VoxelBlock {
  Cell cells[kBlockCells];
  uint64_t touched[kBlockCells / 64] = {};  // per-scan de-dup bits, valid while scan == scan_id
  uint32_t scan_id = 0;                     // scan that last wrote `touched`
  int32_t bx = 0, by = 0, bz = 0;           // block coordinate
  std::vector<VoxelStats> stats;            // dense pool; cells hold indices
  std::vector<uint16_t> free_stats;         // recycled pool slots

  bool test_and_set_touched(int i) {
    const uint64_t bit = uint64_t{1} << (i & 63);
    const bool was = touched[i >> 6] & bit;
    touched[i >> 6] |= bit;
    return was;
  }
  uint16_t alloc_stats() {
    if (!free_stats.empty()) {
      const uint16_t s = free_stats.back();
      free_stats.pop_back();
      stats[s].reset();
      return s;
    }
    stats.emplace_back();
    return uint16_t(stats.size() - 1);
  }
  void release_stats(Cell& c) {
    if (c.stats == Cell::kNoStats) return;
    free_stats.push_back(c.stats);
    c.stats = Cell::kNoStats;
  }
  size_t mem_usage() const {
    return sizeof(*this) + stats.capacity() * sizeof(VoxelStats) +
           free_stats.capacity() * sizeof(uint16_t);
  }
};

}  // namespace storey::core::map
