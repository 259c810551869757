#pragma once
// Baseline `fael-like` (issue 10; in the style of FAEL, Huang et al. 2023): the 3D map is
// projected onto a 2D traversability grid of ONE height band, the floor the robot starts on.
// A cell is free where a traversable support surface lies within fael_band_m of the floor
// height, an obstacle where anything is occupied between floor + fael_obstacle_from_m and the
// body top (walls, furniture, and every elevation change: a stair's treads and a ramp once it
// leaves the band), unknown otherwise. Frontiers are free cells next to unknown ones, clustered
// on the plane; each cluster's viewpoint is its reachable cell nearest the centroid, ranked by a
// gain / cost utility (cells / (1 + path length)); paths come from Dijkstra on the grid
// (obstacles inflated by half the body width + margin, a soft penalty near them) and go through
// the same B-spline and FCL machinery as every method. Stairs being obstacles, it never leaves
// the start floor (what the paper reports for FAEL in multi-floor buildings).
#include <cstdint>
#include <vector>

#include "core/baselines/goal_driver.hpp"

namespace storey::core::baselines {

enum class GridCell : uint8_t { kUnknown = 0, kFree, kObstacle };

// The 2D projection of one height band (see above).
class TraversabilityGrid2D {
 public:
  // floor_z_m: support height of the floor; body_top_m: obstacle band top above it.
  void build(const map::MapView& view, double floor_z_m, double band_m, double obstacle_from_m,
             double body_top_m);
  bool inside(int ix, int iy) const { return ix >= 0 && iy >= 0 && ix < nx_ && iy < ny_; }
  GridCell at(int ix, int iy) const {
    return inside(ix, iy) ? cells_[size_t(iy) * size_t(nx_) + size_t(ix)] : GridCell::kUnknown;
  }
  GridCell at_m(double x, double y) const { return at(ix_of(x), iy_of(y)); }
  float height(int ix, int iy) const { return heights_[size_t(iy) * size_t(nx_) + size_t(ix)]; }
  int ix_of(double x) const { return int(std::floor(x / res_)) - x0_; }
  int iy_of(double y) const { return int(std::floor(y / res_)) - y0_; }
  Eigen::Vector2d centre(int ix, int iy) const {
    return {(ix + x0_ + 0.5) * res_, (iy + y0_ + 0.5) * res_};
  }
  int nx() const { return nx_; }
  int ny() const { return ny_; }
  double resolution() const { return res_; }
  double floor_z() const { return floor_z_; }

 private:
  std::vector<GridCell> cells_;
  std::vector<float> heights_;
  int x0_ = 0, y0_ = 0, nx_ = 0, ny_ = 0;
  double res_ = 0.1, floor_z_ = 0;
};

class FaelLikePlanner {
 public:
  FaelLikePlanner(const RobotModel& robot, const plan::PlanOptions& plan, double voxel_size_m,
                  const BaselineOptions& options = {});
  plan::ExplorationResult plan(const plan::ExplorationInput& in);
  void drop_target() { driver_.drop_target(); }
  const GoalDriver& driver() const { return driver_; }
  const TraversabilityGrid2D& grid() const { return grid_; }
  // Goals of one cycle on the start floor's plane (grid Dijkstra path each), best first.
  std::vector<Goal> goals(const plan::ExplorationInput& in);

 private:
  RobotModel robot_;
  BaselineOptions opt_;
  GoalDriver driver_;
  TraversabilityGrid2D grid_;
  bool have_floor_ = false;
  double floor_z_ = 0;
  std::vector<uint8_t> blocked_;  // inflated obstacles (hard)
  std::vector<uint8_t> near_;     // soft clearance band
  std::vector<double> dist_;
  std::vector<int32_t> parent_;
};

}  // namespace storey::core::baselines
