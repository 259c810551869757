#pragma once
// The hybrid graph G_hybrid = G_real U G_hyp of one target floor and its task zones (paper
// Sec. IV-A last paragraph, IV-B).
//
// G_hyp: the reference floor's graph and zones translated by dz (init_prior). Every node starts
// S_hyp with its zone label; every edge S_hyp. G_real belongs to the map task (ReachableGraph);
// the hybrid graph never edits it: each update() compiles G_real's nodes and edges plus the
// surviving hypotheses into one search graph (CSR) with a state per node and edge, then
// maintains it:
//  Node promotion (IV-B 1). A real node within hyp_promote_radius_m horizontally and
//   hyp_height_window_m vertically of a hypothetical node absorbs it: the hypothesis is bound
//   to that node, which inherits its zone label and its hypothetical edges (the paper's merge
//   "by transferring its edges"; here the edges are re-pointed at compile time). Without such a
//   node, a traversable support surface the map finds in the column (SupportQuery, the graph's
//   own node test) makes the hypothesis itself confirmed (or tentative off C_reach).
//  Edge validation. A hypothetical edge crossing an occupied voxel in the body's height band is
//   pruned; one whose two ends are real is checked as a walk over the support surface
//   (SupportQuery::check_edge): valid -> confirmed/tentative, collision/step/slope/fall ->
//   pruned, unknown ground -> stays hypothetical.
//  Discard. Each new map version on which the column shows no usable surface although it was
//   observed (a support rejected for collision, fall risk or terrain; or no support within the
//   window while the voxels at the projected height and 0.3 m above are known) counts one
//   negative observation; hyp_discard_observations of them discard the hypothesis for good.
//  Hypotheses are only re-checked within hyp_check_radius_m of the robot (the map changes
//   where the robot scans), at most once per map version; when the caller passes the map's
//   changed regions, only those near a change (or that just came within the radius, or whose
//   binding changed) are re-checked: negative evidence then counts once per change near the
//   column instead of once per version (repeated observations, not repeated versions).
//  Zones (IV-B 2, only with incremental_maintenance): 1) connectivity split: per zone, the
//   component of c_k along valid edges inside the zone (the largest one if c_k is isolated or
//   gone) keeps the label, the rest is unassigned; 2) unassigned target-floor nodes (detached
//   ones and newly sampled real nodes) form components by BFS over valid edges; 3) each
//   component merges into an adjacent zone (>= 1 cross edge, node capacity respected) if they
//   share zone_merge_cross_edges edges or their centroids are within zone_merge_distance_m (or
//   it is smaller than min_zone_nodes), else becomes a new zone; 4) centres recomputed.
//   Merging requires a cross edge so a zone never spans two disconnected parts (which the next
//   split would undo). Without maintenance (ablation) labels never change; nodes not in the
//   prior stay unassigned.
//  Zone state (IV-C): H if no member is real; C if no member is a frontier and either no
//   hypothesis is left or the robot has been within zone_visit_radius_m of c_k; else A.
//
// Deterministic; single-threaded (the plan task). Scratch is reused between updates.
#include <cstdint>
#include <span>
#include <vector>

#include <Eigen/Core>

#include "core/graph/reachable_graph.hpp"
#include "core/map/map_view.hpp"
#include "core/plan/floor_tracker.hpp"
#include "core/plan/graph_search.hpp"
#include "core/plan/plan_options.hpp"
#include "core/plan/stage_probe.hpp"
#include "core/plan/task_zones.hpp"

namespace storey::core::plan {

using graph::ElementState;

enum class ZoneState : uint8_t { kHypothetical = 0, kActive = 1, kCompleted = 2 };  // H, A, C
const char* to_string(ZoneState s);

struct HybridNode {
  Eigen::Vector3d p_m = Eigen::Vector3d::Zero();
  ElementState state = ElementState::kHypothetical;
  int32_t zone = -1;                  // zone id, -1 unassigned
  graph::NodeId real = graph::kNoId;  // G_real node, kNoId for a hypothesis standing alone
  bool on_target = false;             // belongs to the target floor (takes part in zones)
  bool frontier = false;              // TF node of G_real
};

struct HybridEdge {
  uint32_t a = 0, b = 0;  // compiled node indices
  ElementState state = ElementState::kHypothetical;
};

struct HybridZone {
  int32_t id = -1;
  std::vector<uint32_t> nodes;  // compiled node indices
  uint32_t centre = kNoNode;    // c_k (compiled index)
  Eigen::Vector3d centroid_m = Eigen::Vector3d::Zero();
  ZoneState state = ZoneState::kHypothetical;
  int real_nodes = 0, hyp_nodes = 0, frontier_nodes = 0;
  bool visited = false;  // robot was within zone_visit_radius_m of c_k
};

struct MaintenanceStats {
  uint32_t bound = 0;      // hypotheses merged with an overlapping real node
  uint32_t promoted = 0;   // hypotheses confirmed by a surface in their column
  uint32_t negative = 0;   // negative observations counted
  uint32_t discarded = 0;  // hypotheses discarded
  uint32_t edges_confirmed = 0, edges_pruned = 0;
  uint32_t split_detached = 0;  // nodes detached by connectivity splits
  uint32_t components = 0;      // unassigned components extracted
  uint32_t merged = 0, new_zones = 0;
  uint32_t hyp_alive = 0;  // hypotheses left (unbound)
};

class HybridGraph {
 public:
  // Builds G_hyp on `target_floor` from the reference floor's graph `ref` (positions, edges)
  // and its partition, translated by dz [m]. Replaces any previous prior.
  void init_prior(const SearchGraph& ref, const ZonePartition& zones, double dz_m,
                  int32_t target_floor);
  void clear();
  bool has_prior() const { return target_floor_ >= 0; }
  int32_t target_floor() const { return target_floor_; }

  // One planning cycle: compile G_real (from `g`, floors labelled by `floors`) with the
  // hypotheses, maintain them (promotion, validation, discard, zones) and classify the zones.
  // `changed`: map regions changed since the previous update (nullptr: unknown, re-check every
  // hypothesis within hyp_check_radius_m on a new version).
  MaintenanceStats update(const map::MapView& view, uint64_t map_version,
                          const graph::ReachableGraph& g, const FloorTracker& floors,
                          const Eigen::Vector3d& robot_foot_m, const PlanOptions& opt,
                          const std::vector<graph::Aabb>* changed = nullptr);

  // Compiled hybrid graph of the last update.
  const SearchGraph& search_graph() const { return csr_; }
  const std::vector<HybridNode>& nodes() const { return nodes_; }
  const std::vector<HybridEdge>& edges() const { return edges_; }
  // CSR edge id -> the edge is real (S_conf / S_tent) and both its ends are real.
  bool csr_edge_real(uint32_t e) const { return csr_real_[e] != 0; }
  bool node_real(uint32_t u) const { return nodes_[u].state != ElementState::kHypothetical; }
  uint32_t node_of_real(graph::NodeId id) const {
    return id < real_index_.size() ? real_index_[id] : kNoNode;
  }
  const std::vector<HybridZone>& zones() const { return zones_; }  // live zones only
  size_t hypotheses_alive() const;
  void set_stage_probe(StageProbe* probe) { probe_ = probe; }

 private:
  struct HypNode {
    Eigen::Vector3d p_m;
    int32_t zone;
    ElementState state = ElementState::kHypothetical;  // kConf/kTent once promoted alone
    graph::NodeId bound = graph::kNoId;                // merged into this real node
    Eigen::Vector3f bound_p;                           // its position then (id recycling)
    uint8_t negative = 0;
    bool alive = true;
    uint32_t in_range = 0;  // last check cycle it was within hyp_check_radius_m
    uint32_t touched = 0;   // check cycle in which it was re-checked or (un)bound
  };
  struct HypEdge {
    uint32_t a, b;  // hyp indices
    ElementState state = ElementState::kHypothetical;
    bool alive = true;
    uint32_t in_range = 0;
  };
  struct ZoneRec {
    bool alive = true;
    bool visited = false;
    // c_k as a stable reference: a hypothesis index or a real node id (+ its position).
    int32_t centre_hyp = -1;
    graph::NodeId centre_real = graph::kNoId;
  };

  void check_hypotheses(const map::MapView& view, const graph::ReachableGraph& g,
                        const Eigen::Vector3d& robot, const PlanOptions& opt,
                        const std::vector<graph::Aabb>* changed, MaintenanceStats& st);
  void bind_real_nodes(const graph::ReachableGraph& g, const FloorTracker& floors,
                       const PlanOptions& opt, MaintenanceStats& st);
  void compile(const map::MapView& view, const graph::ReachableGraph& g, const FloorTracker& floors,
               const PlanOptions& opt);
  void maintain_zones(const PlanOptions& opt, MaintenanceStats& st);
  void collect_zones(const Eigen::Vector3d& robot, const PlanOptions& opt);
  uint32_t centre_index(const ZoneRec& z) const;
  void set_label(uint32_t u, int32_t zone);
  bool segment_blocked(const map::MapView& view, const Eigen::Vector3d& a,
                       const Eigen::Vector3d& b) const;
  uint64_t cell(double x, double y) const;

  int32_t target_floor_ = -1;
  StageProbe* probe_ = nullptr;
  std::vector<HypNode> hyp_;
  std::vector<HypEdge> hyp_edges_;
  std::vector<std::vector<uint32_t>> hyp_adj_;           // hyp node -> hyp edge ids
  std::vector<std::pair<uint64_t, uint32_t>> hyp_grid_;  // (horizontal cell, hyp id), sorted
  double grid_m_ = 1.0;
  std::vector<ZoneRec> zone_recs_;
  uint64_t last_version_ = ~uint64_t(0);
  uint32_t check_cycle_ = 1;  // check_hypotheses calls + 1 (0 = "never" in HypNode::in_range)
  // Zone labels of real nodes by id, with the position they had when labelled (ids recycle).
  std::vector<int32_t> real_zone_;
  std::vector<Eigen::Vector3f> real_zone_p_;

  // Compiled.
  std::vector<HybridNode> nodes_;
  std::vector<HybridEdge> edges_;
  std::vector<uint32_t> real_index_;  // real id -> compiled index
  std::vector<uint32_t> hyp_index_;   // hyp id -> compiled index (bound: the real node's)
  std::vector<int32_t> node_hyp_;     // compiled index -> hyp id standing alone, else -1
  SearchGraph csr_;
  std::vector<uint8_t> csr_real_;
  std::vector<HybridZone> zones_;
  // Scratch.
  std::vector<graph::NodeId> near_;
  std::vector<uint32_t> stack_, comp_, deg_;
  std::vector<int32_t> mark_;
  std::vector<int> cross_;
};

}  // namespace storey::core::plan
