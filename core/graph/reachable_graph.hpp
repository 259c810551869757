#pragma once
// The incremental reachable graph G_real = (V_real, E_real) of paper Sec. III-B.
//
// Nodes sit at support positions (x, y, surface height); edges are collision-free transitions
// over the support surface (SupportQuery::check_edge). Elements are confirmed (fully supported
// by C_reach) or tentative (collision-free, no fall risk, over under-observed ground). Every map
// cycle, update() re-evaluates only the affected subgraph: nodes inside the changed regions and
// nodes whose C_reach membership flipped (promotion / demotion), prunes what meets new
// obstacles, expands by Eq. 4 from queued nodes, and after any removal drops the components no
// longer connected to the robot (BFS from the robot's node). Work per cycle is bounded by the
// revalidation and expansion budgets; what is left carries over (see pending()).
//
// Ids are stable (a free list recycles them). Single-threaded: the map task owns the graph;
// readers on other threads get a copy.
#include <array>
#include <cstdint>
#include <deque>
#include <limits>
#include <random>
#include <span>
#include <unordered_map>
#include <vector>

#include <Eigen/Core>

#include "core/graph/graph_options.hpp"
#include "core/graph/support_query.hpp"
#include "core/map/map_view.hpp"

namespace storey::core::graph {

using NodeId = uint32_t;
using EdgeId = uint32_t;
inline constexpr uint32_t kNoId = std::numeric_limits<uint32_t>::max();

// Axis-aligned box [m]: a region of the map that changed since the last update.
struct Aabb {
  Eigen::Vector3f lo = Eigen::Vector3f::Constant(std::numeric_limits<float>::infinity());
  Eigen::Vector3f hi = Eigen::Vector3f::Constant(-std::numeric_limits<float>::infinity());
  void extend(const Eigen::Vector3f& p) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  bool empty() const { return !(lo.x() <= hi.x()); }
  Aabb inflated(float m) const { return empty() ? *this : Aabb{lo.array() - m, hi.array() + m}; }
  bool contains(const Eigen::Vector3f& p) const {
    return (p.array() >= lo.array()).all() && (p.array() <= hi.array()).all();
  }
};
// Bounds of one scan (origin and returns): what insert_scan() can have changed. Non-finite
// points are skipped (the map drops them too).
Aabb scan_bounds(const Eigen::Vector3f& origin_m, std::span<const Eigen::Vector3f> points_m);

struct GraphNode {
  static constexpr int kMaxDegree = 16;           // compile-time bound of k_max
  Eigen::Vector3f p_m = Eigen::Vector3f::Zero();  // support position p_i
  map::VoxelKey key;                              // its support voxel
  ElementState state = ElementState::kTentative;
  bool alive = false;
  // Topological frontier flags (Sec. III-C), written by TopologicalFrontiers.
  bool c_sur = false, c_exp = false;  // criteria C_sur (Eq. 5) and C_exp
  bool boundary = false;              // ablation: near the geometric boundary of C_reach
  // Not a frontier: a C_exp probe climbed a flight onto treads out of C_reach (climb_frontiers).
  // The graph cannot follow a flight whose treads' backs, shadowed by the next riser, are unseen;
  // a blind climb from its foot can (LocalPlanner, once a floor has no other target).
  bool flight_lead = false;
  float rho = 0;           // rho_i, Eq. 5
  uint8_t open_dirs = 0;   // |Theta_i^open|
  int16_t floor_hint = 0;  // round(z / floor_height_hint_m)
  int32_t cluster = -1;    // frontier cluster id, -1 if none
  uint8_t degree = 0;
  uint8_t queued = 0;  // kQueued* bits
  std::array<EdgeId, kMaxDegree> edges{};
  bool frontier() const { return c_sur || c_exp || boundary; }

  static constexpr uint8_t kQueuedExpand = 1, kQueuedRevalidate = 2, kTouched = 4;
};

struct GraphEdge {
  NodeId a = kNoId, b = kNoId;
  ElementState state = ElementState::kTentative;
  bool alive = false;
  float length_m = 0;    // along the support surface
  float cost = 0;        // length * (1 + mean c(v)), Eq. 2 along the edge
  uint32_t checked = 0;  // update cycle that last re-checked it (each edge once per cycle)
  NodeId other(NodeId n) const { return n == a ? b : a; }
};

struct GraphUpdateStats {
  uint32_t revalidated = 0;  // nodes re-checked (with their edges)
  uint32_t expanded = 0;     // nodes expanded (Eq. 4)
  uint32_t nodes_added = 0, edges_added = 0;
  uint32_t nodes_pruned = 0;  // removed: support lost, new obstacle, fall risk
  uint32_t edges_pruned = 0;
  uint32_t promoted = 0;        // S_tent -> S_conf (nodes and edges)
  uint32_t demoted = 0;         // S_conf -> S_tent (left C_reach but still valid)
  uint32_t disconnected = 0;    // nodes removed by the BFS from the robot
  uint32_t relinked = 0;        // edges added across a cut (GraphOptions::relink_cuts)
  bool prune_deferred = false;  // cut off from the robot but the larger part: kept for now
  uint32_t pending_revalidations = 0, pending_expansions = 0;  // carried over
  uint32_t rejects[int(Reject::kCount)] = {};  // candidate nodes / edges rejected, by reason
  bool has_root = false;
  bool root_isolated = false;  // robot's node has no edge: component pruning skipped
};

class ReachableGraph {
 public:
  explicit ReachableGraph(const GraphOptions& opt = {});

  // One map cycle. `view`: the map after update_traversability() and update_reachable();
  // `robot_foot_m`: a point on the ground under the robot; `changed`: regions of the map that
  // changed since the last call (e.g. scan_bounds of the scans inserted); `rng`: the seeded
  // generator for theta ~ U(0, 2pi) (same seed and inputs -> same graph, bit for bit).
  GraphUpdateStats update(const map::MapView& view, const Eigen::Vector3f& robot_foot_m,
                          std::span<const Aabb> changed, std::mt19937_64& rng);
  // Queues every node for revalidation and expansion (e.g. after the options changed).
  void touch_all();
  // Per-update work limits (see GraphOptions::max_*_per_update).
  void set_budgets(int revalidations, int expansions, int /*reserved*/) {
    opt_.max_revalidations_per_update = revalidations;
    opt_.max_expansions_per_update = expansions;
  }
  // Queues one node for expansion at the next update (a new topological frontier).
  void request_expand(NodeId i) {
    if (i < nodes_.size() && nodes_[i].alive) queue_expand(i);
  }
  bool idle() const { return expand_q_.empty() && reval_q_.empty() && deferred_updates_ == 0; }

  const GraphNode& node(NodeId i) const { return nodes_[i]; }
  const GraphEdge& edge(EdgeId e) const { return edges_[e]; }
  // Frontier flags and cluster ids are written by TopologicalFrontiers / FrontierClusters.
  GraphNode& mutable_node(NodeId i) { return nodes_[i]; }
  size_t node_capacity() const { return nodes_.size(); }  // ids are < this
  size_t edge_capacity() const { return edges_.size(); }
  size_t node_count() const { return node_count_; }
  size_t edge_count() const { return edge_count_; }
  NodeId root() const { return root_; }
  EdgeId find_edge(NodeId a, NodeId b) const;

  // Nodes whose position is within horizontal radius r and |dz| <= dz of p (unordered).
  void nodes_within(const Eigen::Vector3f& p, float r, float dz, std::vector<NodeId>& out) const;
  NodeId nearest(const Eigen::Vector3f& p, float r, float dz) const;
  // Nodes touched (created, revalidated, edges changed) since the last call; cleared by it.
  void take_touched(std::vector<NodeId>& out);

  const GraphOptions& options() const { return opt_; }
  size_t mem_usage() const;

 private:
  NodeId add_node(const Support& s, bool confirmed);
  void remove_node(NodeId i);
  EdgeId add_edge(NodeId a, NodeId b, const EdgeCheck& ec);
  void remove_edge(EdgeId e);
  bool direction_ok(NodeId i, const Eigen::Vector3f& towards) const;
  bool try_connect(SupportQuery& q, NodeId i, NodeId j, GraphUpdateStats& st);
  ElementState edge_state(NodeId a, NodeId b, const EdgeCheck& ec) const;
  void revalidate(SupportQuery& q, NodeId i, GraphUpdateStats& st);
  void expand(SupportQuery& q, NodeId i, std::mt19937_64& rng, GraphUpdateStats& st);
  NodeId attach_root(SupportQuery& q, const Eigen::Vector3f& foot, GraphUpdateStats& st);
  void prune_disconnected(GraphUpdateStats& st);
  void relink_cut(SupportQuery& q, GraphUpdateStats& st);
  void mark_root_component();
  void queue_expand(NodeId i);
  void queue_revalidate(NodeId i);
  void touch(NodeId i);
  uint64_t cell_of(const Eigen::Vector3f& p) const;
  uint64_t cell_key(int32_t x, int32_t y, int32_t z) const;

  GraphOptions opt_;
  std::vector<GraphNode> nodes_;
  std::vector<GraphEdge> edges_;
  std::vector<NodeId> free_nodes_;
  std::vector<EdgeId> free_edges_;
  size_t node_count_ = 0, edge_count_ = 0;
  NodeId root_ = kNoId;
  bool connectivity_lost_ = false;
  int deferred_updates_ = 0;  // updates the current cut has been deferred (0: none pending)
  std::deque<NodeId> expand_q_, reval_q_;
  std::vector<NodeId> touched_;
  // Spatial hash over nodes: cubic cells of r_e.
  float cell_m_;
  std::unordered_map<uint64_t, std::vector<NodeId>> grid_;
  // Scratch (reused; no allocation in steady state once grown).
  std::vector<NodeId> scratch_, bfs_;
  std::vector<Aabb> boxes_;
  std::vector<uint32_t> mark_;
  uint32_t mark_epoch_ = 0;
  uint32_t cycle_ = 0;
  std::vector<std::pair<float, std::pair<NodeId, NodeId>>> bridges_;  // relink_cut's candidates
};

}  // namespace storey::core::graph
