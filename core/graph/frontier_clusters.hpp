#pragma once
// Clustering of topological frontier nodes (paper Sec. III-C): frontier nodes are merged with
// connected frontier neighbours along graph edges (BFS restricted to V_TF) up to
// cluster_capacity nodes. Edges never cross walls, so neither do clusters. The centroid of a
// cluster is its representative location. Cluster ids are kept stable across updates where
// possible: a new cluster inherits the id of the previous cluster most of its nodes belonged
// to (first come, first served in seed order), else takes a fresh id.
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "core/graph/reachable_graph.hpp"

namespace storey::core::graph {

struct FrontierCluster {
  int32_t id = -1;
  std::vector<NodeId> nodes;  // TF nodes, BFS order from the seed
  Eigen::Vector3f centroid_m = Eigen::Vector3f::Zero();
  int confirmed = 0;  // confirmed members (planners may prefer them)
};

class FrontierClusters {
 public:
  explicit FrontierClusters(const GraphOptions& opt = {}) : opt_(opt) {}
  // Recomputes the clusters from the frontier flags and writes GraphNode::cluster.
  const std::vector<FrontierCluster>& update(ReachableGraph& g);
  const std::vector<FrontierCluster>& clusters() const { return clusters_; }

 private:
  GraphOptions opt_;
  std::vector<FrontierCluster> clusters_;
  std::vector<int32_t> prev_;  // previous cluster id per node id
  std::vector<uint8_t> seen_;
  std::vector<int32_t> votes_ids_;
  std::vector<int> votes_n_;
  std::vector<uint8_t> id_taken_;
  int32_t next_id_ = 0;
};

}  // namespace storey::core::graph
