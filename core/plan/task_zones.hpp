#pragma once
// Task-zone partition of a floor's graph (paper Sec. IV-A).
//
// Seeds: the unassigned node with the largest horizontal distance to the nearest obstacle (so
// zone centres sit in open space, not against walls); ties by the lower node index. From each
// seed a bounded Dijkstra along the graph's edges claims every node within path length r_z;
// a node already covered by an earlier zone moves to the new one only if the new seed's path is
// strictly shorter (a geodesic Voronoi partition restricted to r_z balls, so every zone stays
// connected along edges). Repeat until every node is covered; then zones with fewer than
// min_zone_nodes nodes are absorbed into the adjacent zone sharing the most cross edges
// (isolated small zones stay). Centre c_k = the zone's node nearest its spatial centroid.
// Because zones grow along graph edges, and edges never pass through walls, a zone never
// spans a wall except through a doorway the graph crosses.
//
// Deterministic (ties by index). The partitioner keeps its scratch between calls.
#include <cstdint>
#include <span>
#include <vector>

#include <Eigen/Core>

#include "core/map/map_view.hpp"
#include "core/plan/graph_search.hpp"

namespace storey::core::plan {

struct TaskZone {
  int32_t id = -1;
  std::vector<uint32_t> nodes;  // graph node indices, ascending
  uint32_t centre = kNoNode;    // c_k: the member nearest the centroid
  Eigen::Vector3d centroid_m = Eigen::Vector3d::Zero();
};

struct ZonePartition {
  std::vector<int32_t> zone_of;  // per graph node: index into zones (== TaskZone::id), -1 none
  std::vector<TaskZone> zones;   // ids 0..M-1
};

struct ZoneOptions {
  double r_z_m = 6.0;      // r_z, bounded Dijkstra radius along the graph
  int min_zone_nodes = 4;  // smaller zones are absorbed into the neighbour with most cross edges
};

// Centroid and centre c_k of a zone from the node positions (members must be non-empty).
void compute_zone_centre(std::span<const Eigen::Vector3d> positions_m, TaskZone& z);

class TaskZonePartitioner {
 public:
  // g: the floor's graph (undirected CSR, weights = path lengths [m]); clearance_m: per node,
  // horizontal distance to the nearest obstacle [m] (seed priority). Sizes must match, else an
  // empty partition with every node at -1 is returned (counted in bad_input()).
  ZonePartition partition(const SearchGraph& g, std::span<const double> clearance_m,
                          const ZoneOptions& opt);
  uint32_t bad_input() const { return bad_input_; }

 private:
  GraphSearch search_;
  std::vector<double> best_;
  std::vector<uint32_t> order_;
  uint32_t bad_input_ = 0;
};

// Horizontal distance from a support point to the nearest obstacle: an occupied voxel in the
// body's height band (from one step above the surface to the body height, the layers a wall
// occupies and a floor or a low kerb does not). Bounded search over the columns within
// max_radius_m, nearest first, first hit wins; max_radius_m if none (open space beyond the
// radius ranks equal). Cost: at most pi (R/voxel)^2 columns x band layers.
class ObstacleClearance {
 public:
  explicit ObstacleClearance(double max_radius_m = 3.0) : max_radius_m_(max_radius_m) {}
  double operator()(const map::MapView& view, const Eigen::Vector3f& support_m);
  // The same for many points (a floor's nodes): each column is looked up at most once per
  // group of points within 64 layers (a floor), so a floor costs its columns x layers instead
  // of points x pi (R/voxel)^2 x layers. out[i] == operator()(view, points[i]).
  void operator()(const map::MapView& view, std::span<const Eigen::Vector3f> points,
                  std::vector<double>& out);

 private:
  void build(double voxel_m);
  // Column memo over a box of columns: occupied layers (bit i = layer z0 + i), evaluated yet.
  std::vector<uint64_t> mask_;
  std::vector<uint8_t> done_;
  std::vector<uint32_t> order_;
  double max_radius_m_;
  double built_for_voxel_m_ = 0;
  struct Offset {
    int16_t dx, dy;
    float dist_m;
  };
  std::vector<Offset> offsets_;  // columns within the radius, nearest first
};

}  // namespace storey::core::plan
