#pragma once
// Candidate viewpoints per frontier cluster (paper Sec. III-C, last paragraph): graph nodes
// near the cluster, yaw facing the centroid, scored by the number of the cluster's TF nodes a
// simulated LiDAR at that node would see (field of view, range, occlusion by occupied voxels
// of the map; unknown space does not occlude). The best K are kept per cluster.
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "core/graph/frontier_clusters.hpp"
#include "core/graph/reachable_graph.hpp"

namespace storey::core::graph {

// The LiDAR's field of view in the robot's (level) body frame.
struct SensorFov {
  double v_min_deg = -15.0;     // lowest beam elevation
  double v_max_deg = 15.0;      // highest beam elevation
  double h_fov_deg = 360.0;     // horizontal field of view, centred on the yaw
  double max_range_m = 30.0;    // usable range
  double mount_height_m = 0.5;  // sensor origin above the support surface
  static SensorFov vlp16() { return {-15.0, 15.0, 360.0, 30.0, 0.5}; }
  static SensorFov mid360() { return {-7.0, 52.0, 360.0, 30.0, 0.5}; }
};

struct Viewpoint {
  NodeId node = kNoId;
  Eigen::Vector3f p_m = Eigen::Vector3f::Zero();  // support position of the node
  float yaw_rad = 0;                              // facing the cluster centroid
  int visible = 0;                                // TF nodes of the cluster seen from here
  ElementState state = ElementState::kTentative;
};

struct ClusterViewpoints {
  int32_t cluster_id = -1;
  std::vector<Viewpoint> viewpoints;  // best first, at most viewpoints_per_cluster
};

class ViewpointGenerator {
 public:
  explicit ViewpointGenerator(const GraphOptions& opt = {}, const SensorFov& fov = {})
      : opt_(opt), fov_(fov) {}

  // Viewpoints of one cluster into `out` (cleared first). Candidates: nodes within
  // viewpoint_radius_m of the centroid and the cluster's own nodes.
  void generate(const ReachableGraph& g, const map::MapView& view, const FrontierCluster& c,
                std::vector<Viewpoint>& out);
  const std::vector<ClusterViewpoints>& update(const ReachableGraph& g, const map::MapView& view,
                                               const std::vector<FrontierCluster>& clusters);
  const std::vector<ClusterViewpoints>& viewpoints() const { return out_; }
  // Is `target` inside the field of view of a sensor at `origin` looking along `yaw`, within
  // range and not occluded by an occupied voxel?
  bool visible(SupportQuery& q, const Eigen::Vector3f& origin, float yaw,
               const Eigen::Vector3f& target) const;

 private:
  GraphOptions opt_;
  SensorFov fov_;
  std::vector<ClusterViewpoints> out_;
  std::vector<NodeId> cand_;
  std::vector<Viewpoint> scored_;
};

}  // namespace storey::core::graph
