#include "core/graph/frontier_clusters.hpp"

#include <algorithm>

namespace storey::core::graph {

const std::vector<FrontierCluster>& FrontierClusters::update(ReachableGraph& g) {
  const size_t cap = g.node_capacity();
  prev_.resize(cap, -1);
  seen_.assign(cap, 0);
  for (NodeId i = 0; i < cap; ++i) {
    prev_[i] = g.node(i).alive ? g.node(i).cluster : -1;
    g.mutable_node(i).cluster = -1;
  }
  const size_t capacity = size_t(std::max(1, opt_.cluster_capacity));
  size_t used = 0;
  // Seeds in id order (deterministic); BFS over edges between frontier nodes.
  for (NodeId s = 0; s < cap; ++s) {
    const GraphNode& sn = g.node(s);
    if (!sn.alive || !sn.frontier() || seen_[s]) continue;
    if (used == clusters_.size()) clusters_.emplace_back();
    FrontierCluster& c = clusters_[used++];
    c.nodes.clear();
    c.nodes.push_back(s);
    seen_[s] = 1;
    for (size_t h = 0; h < c.nodes.size() && c.nodes.size() < capacity; ++h) {
      const NodeId u = c.nodes[h];
      const GraphNode& un = g.node(u);
      for (int k = 0; k < un.degree && c.nodes.size() < capacity; ++k) {
        const NodeId v = g.edge(un.edges[k]).other(u);
        if (seen_[v] || !g.node(v).frontier()) continue;
        seen_[v] = 1;
        c.nodes.push_back(v);
      }
    }
    c.centroid_m.setZero();
    c.confirmed = 0;
    for (NodeId n : c.nodes) {
      c.centroid_m += g.node(n).p_m;
      c.confirmed += g.node(n).state == ElementState::kConfirmed;
    }
    c.centroid_m /= float(c.nodes.size());
  }
  clusters_.resize(used);

  // Stable ids: majority vote of the previous ids of the members.
  id_taken_.assign(size_t(next_id_), 0);
  for (FrontierCluster& c : clusters_) {
    votes_ids_.clear();
    votes_n_.clear();
    for (NodeId n : c.nodes) {
      const int32_t p = prev_[n];
      if (p < 0 || p >= next_id_ || id_taken_[size_t(p)]) continue;
      auto it = std::find(votes_ids_.begin(), votes_ids_.end(), p);
      if (it == votes_ids_.end()) {
        votes_ids_.push_back(p);
        votes_n_.push_back(1);
      } else {
        ++votes_n_[size_t(it - votes_ids_.begin())];
      }
    }
    int32_t id = -1;
    int best = 0;
    for (size_t k = 0; k < votes_ids_.size(); ++k)
      if (votes_n_[k] > best || (votes_n_[k] == best && votes_ids_[k] < id)) {
        best = votes_n_[k];
        id = votes_ids_[k];
      }
    if (id < 0) {
      id = next_id_++;
      id_taken_.push_back(0);
    }
    id_taken_[size_t(id)] = 1;
    c.id = id;
    for (NodeId n : c.nodes) g.mutable_node(n).cluster = id;
  }
  return clusters_;
}

}  // namespace storey::core::graph
