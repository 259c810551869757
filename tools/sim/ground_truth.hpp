// Ground truth of a world mesh at the map resolution (DESIGN §5, §7): occupied voxels (surface
// voxelisation), traversable support voxels reachable by the robot from its start pose, floors
// found as clusters of support heights, volumes and per-floor areas. Works for any mesh.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "tools/sim/mesh.hpp"
#include "tools/sim/scene.hpp"

namespace storey::tools::sim {

// Integer voxel coordinates: key = floor(p / resolution). A surface exactly on a voxel boundary
// (z = 3.0 at 0.1 m) belongs to the voxel above it (a 1e-4-voxel bias removes float ambiguity).
struct VoxelKey {
  int32_t x = 0, y = 0, z = 0;
  bool operator==(const VoxelKey&) const = default;
};
struct VoxelKeyHash {
  std::size_t operator()(const VoxelKey& k) const {
    return (static_cast<std::size_t>(static_cast<uint32_t>(k.x)) * 73856093u) ^
           (static_cast<std::size_t>(static_cast<uint32_t>(k.y)) * 19349663u) ^
           (static_cast<std::size_t>(static_cast<uint32_t>(k.z)) * 83492791u);
  }
};
VoxelKey voxel_key(const Eigen::Vector3d& p, double resolution);

struct GroundTruthOptions {
  double resolution = 0.1;       // [m], the map's voxel size (DESIGN §4)
  double body_clearance = 0.45;  // [m] free space above support: Go2 body 0.40 m + margin
  double step_height = 0.18;     // [m] largest step between neighbouring support voxels
  // [m] horizontal clearance: the map's R_col (map.collision_radius_m, paper III-A Eq. 3). A
  // support voxel is traversable truth only if no occupied voxel whose geometry reaches into
  // (step_height, body_clearance] above the support surface lies within this horizontal radius
  // (in voxels ceil(r / resolution), disc dx^2 + dy^2 <= r^2 as in core/map). 0: no clearance.
  double collision_radius = 0.1;
  double max_slope_deg = 30.0;  // [deg] steepest walkable surface (triangle normal)
  double floor_min_area = 8.0;  // [m^2] a support height with less area is not a floor
};

struct FloorTruth {
  double z_m = 0.0;                  // floor height [m]: support voxel index x resolution
  double traversable_area_m2 = 0.0;  // reachable support voxels nearest this floor x res^2
  std::size_t voxels = 0;
};

class GroundTruth {
 public:
  // Voxelises `mesh` and flood-fills the reachable support from `start` (or, without one, from
  // the middle of the lowest floor-sized support level). Throws std::runtime_error when the
  // mesh is empty or no support is found near the start.
  GroundTruth(const Mesh& mesh, const std::optional<StartPose>& start,
              const GroundTruthOptions& options = {});

  const GroundTruthOptions& options() const { return opt_; }
  double resolution() const { return opt_.resolution; }
  const Aabb& bounds() const { return bounds_; }
  const StartPose& start() const { return start_; }
  VoxelKey start_voxel() const { return start_voxel_; }

  bool occupied(const VoxelKey& k) const { return flag(k, kOccupied); }
  bool support(const VoxelKey& k) const { return flag(k, kSupport); }      // any support voxel
  bool reachable(const VoxelKey& k) const { return flag(k, kReachable); }  // traversable truth
  // Support voxel with horizontal clearance (no obstacle within collision_radius), reachable
  // or not.
  bool clear(const VoxelKey& k) const { return flag(k, kSupport) && flag(k, kClear); }
  const std::vector<VoxelKey>& reachable_voxels() const { return reachable_; }
  std::size_t occupied_count() const { return occupied_count_; }

  const std::vector<FloorTruth>& floors() const { return floors_; }
  // Index of the floor nearest in height to voxel k (every reachable voxel has one; -1 when no
  // floor was found).
  int floor_of(const VoxelKey& k) const;

  double traversable_volume_m3() const;  // reachable support voxels x res^3
  double occupied_volume_m3() const;     // occupied surface voxels x res^3

  // Dense grid access for pictures: keys from min_key() to min_key() + dims() - 1.
  VoxelKey min_key() const { return min_; }
  Eigen::Vector3i dims() const { return {nx_, ny_, nz_}; }

  // JSON of DESIGN §7 `--describe`: bbox, floors (z_m, traversable_area_m2), volumes.
  std::string describe_json(const std::string& scene_name) const;

 private:
  static constexpr uint8_t kOccupied = 1, kWalkable = 2, kSupport = 4, kReachable = 8, kClear = 16;
  bool inside(const VoxelKey& k) const {
    return k.x >= min_.x && k.y >= min_.y && k.z >= min_.z && k.x < min_.x + nx_ &&
           k.y < min_.y + ny_ && k.z < min_.z + nz_;
  }
  std::size_t index(const VoxelKey& k) const {
    return (static_cast<std::size_t>(k.z - min_.z) * ny_ + (k.y - min_.y)) * nx_ + (k.x - min_.x);
  }
  bool flag(const VoxelKey& k, uint8_t f) const { return inside(k) && (grid_[index(k)] & f); }
  // Per-voxel lowest / highest surface sample inside the voxel, in 1/255 of a voxel above its
  // bottom face (only meaningful for occupied voxels); used during construction only.
  struct SampleHeights {
    std::vector<uint8_t> lo, hi;
  };
  void voxelise(const Mesh& mesh, SampleHeights& h);
  void find_support();
  void find_clearance(const SampleHeights& h);
  VoxelKey find_start(const std::optional<StartPose>& start);
  void flood_fill();
  void find_floors();

  GroundTruthOptions opt_;
  Aabb bounds_;
  VoxelKey min_;
  int nx_ = 0, ny_ = 0, nz_ = 0;
  std::vector<uint8_t> grid_;
  std::vector<VoxelKey> reachable_;
  std::vector<FloorTruth> floors_;
  std::size_t occupied_count_ = 0;
  StartPose start_;
  VoxelKey start_voxel_;
};

}  // namespace storey::tools::sim
