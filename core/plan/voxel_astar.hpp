#pragma once
// Stage 3 of local planning (paper Sec. IV-D): A* through the free voxels above the traversable
// surface, from the robot to the chosen viewpoint.
//
// States are support voxels (occupied, voxel above not occupied) that are
//   - traversable, tau(v) = S_trav (Eq. 3: slope, roughness and under-observation within tau_c,
//     no collision or fall risk), and members of C_reach unless reachable_only is off;
//   - clear above: is_free_above(v, body height + margin), the body's column;
//   - clear around: no occupied voxel within inflation_radius_m horizontally between
//     h + step_height_m and h + body_height + margin (the same ground rule as the FCL checker,
//     so an A* path is one the box can follow when heading along it).
// Moves go to the 8 horizontal neighbours' support voxel whose surface height is within
// step_height_m of the current one (stairs); diagonals need both side neighbours passable (no
// corner cutting). The slope limit is the map's: a voxel steeper than max_slope is not S_trav.
// Step cost = 3D distance between surface points * (1 + cost_weight * c(v') + clearance_weight *
// near(v')), c(v') of Eq. 2, near(v') = an obstacle within soft_radius_m (see the options).
#include <cstdint>
#include <unordered_map>
#include <vector>

#include <Eigen/Core>

#include "core/map/map_view.hpp"

namespace storey::core::plan {

struct VoxelAStarOptions {
  bool reachable_only = true;    // states must be in C_reach (else S_trav suffices)
  bool unknown_is_free = false;  // unknown voxels in the body column count as free
  double cost_weight = 1.0;      // terrain cost weighting of each step
  uint32_t max_expansions = 200000;
  double goal_tolerance_m = 0.25;  // any state this close (horizontally, same level) reaches it
  double snap_window_m = 0.5;      // vertical search for the support under start / goal [m]
  double inflation_radius_m = -1;  // horizontal clearance; < 0: half body width + margin
  // Soft clearance: a state with an obstacle within this radius (sampled on two rings, 16
  // columns each) costs (1 + clearance_weight) more per metre, so paths keep the long body
  // (0.8 m box) off corners where there is room; < 0: half body length + margin.
  double soft_radius_m = -1;
  double clearance_weight = 1.0;
};

enum class VoxelAStarStatus : uint8_t {
  kOk = 0,
  kBadInput,         // non-finite start/goal
  kNoStartSupport,   // no support voxel under the start within snap_window_m
  kNoGoalSupport,    // no support voxel under the goal within snap_window_m
  kGoalNotPassable,  // the goal's support exists but no passable state lies within tolerance
  kNoPath,           // the open set ran empty: goal not connected through passable states
  kExpansionLimit,   // max_expansions reached first (bounded search)
};
const char* to_string(VoxelAStarStatus s);

struct VoxelPath {
  VoxelAStarStatus status = VoxelAStarStatus::kBadInput;
  std::vector<Eigen::Vector3d> points_m;  // surface points (voxel centre x, y; surface height)
  std::vector<map::VoxelKey> keys;        // support voxels, start ... goal
  double cost = 0;
  uint32_t expansions = 0;
};

class VoxelAStar {
 public:
  explicit VoxelAStar(const VoxelAStarOptions& options = {}) : opt_(options) {}

  // start_m / goal_m: points near the support surface (the robot's foot point, a viewpoint).
  VoxelPath plan(const map::MapView& view, const Eigen::Vector3d& start_m,
                 const Eigen::Vector3d& goal_m);

  // Whether a support voxel is a valid state (exposed for tests and for callers snapping
  // viewpoints); uses the same memo as the search only during plan().
  bool passable(const map::MapView& view, const map::VoxelKey& k, float surface_h) const;
  // Obstacle (above step height, below the body top) within soft_radius_m of the state.
  bool near_obstacle(const map::MapView& view, const map::VoxelKey& k, float surface_h) const;

  const VoxelAStarOptions& options() const { return opt_; }

 private:
  struct Node {
    map::VoxelKey key;
    float h_m;  // surface height
    bool near;  // near_obstacle()
    double g;   // cost so far
    uint32_t parent;
    bool closed;
  };
  struct HeapItem {
    double f;
    uint32_t node;
    bool operator>(const HeapItem& o) const { return f > o.f || (f == o.f && node > o.node); }
  };
  // Support voxel of column (x, y) within step height of h, passable; memoised per search.
  // Returns the node index or kNone.
  uint32_t neighbour(const map::MapView& view, int32_t x, int32_t y, float h);

  static constexpr uint32_t kNone = 0xFFFFFFFFu;
  VoxelAStarOptions opt_;
  std::vector<Node> nodes_;
  std::unordered_map<uint64_t, uint32_t> index_;    // packed key -> node
  std::unordered_map<uint64_t, uint8_t> passable_;  // packed key -> 0 / kPass [| kNear] memo
  static constexpr uint8_t kPass = 1, kNear = 2;
  std::vector<HeapItem> heap_;
};

}  // namespace storey::core::plan
