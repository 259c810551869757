#pragma once
// Topological frontiers on the nodes of G_real (paper Sec. III-C):
//   C_sur(n_i): rho_i = 1 - (1/|Omega_i|) sum_x I(x, z_i) >= rho_min (Eq. 5), Omega_i a disc of
//               radius surface_radius_factor * r_e around the node;
//   C_exp(n_i): |Theta_i^open| >= Theta_min, radial probes along directions not covered by
//               edges, open if they cross known free space and reach unknown without obstacle;
//   n_i in V_TF <=> C_sur or C_exp (each switchable for the ablations).
// Ablation "boundary frontiers": a node is a frontier iff a voxel of the geometric boundary of
// C_reach (a reachable voxel with an unknown / unobserved neighbour column) lies within
// boundary_radius_m of it.
//
// Incremental: only nodes the graph touched and nodes near changed map regions are
// re-evaluated, at most max_frontier_updates per update (nearest the robot first); the rest
// carries over.
#include <cstdint>
#include <deque>
#include <span>
#include <vector>

#include <Eigen/Core>

#include "core/graph/reachable_graph.hpp"
#include "core/graph/support_query.hpp"

namespace storey::core::graph {

struct FrontierUpdateStats {
  uint32_t evaluated = 0;
  uint32_t frontiers = 0;  // |V_TF| after the update
  uint32_t c_sur = 0, c_exp = 0, boundary = 0;
  uint32_t pending = 0;
};

// One C_exp probe's outcome: open (Sec. III-C), blocked by an obstacle (or a hole in a
// surface), or neither (ran out in known free space, or started in unknown space).
enum class ProbeState : uint8_t { kOther = 0, kOpen, kBlocked };
// GraphOptions::passage_frontiers: the open probes of a ring (probes in angular order) whose
// two neighbours are both blocked: a corridor or door one probe wide, walls either side
// (test_ramp's upper corridors' ends, session 28). A neighbour that ran out in known free space (a
// door seen from its room's side) or started in unknown space does not count (session 26's rule let
// one of them count).
int passage_probes(std::span<const ProbeState> ring);

// One C_exp probe of a node, explained (diagnostics: why a node is a frontier).
struct ProbeExplanation {
  float theta_rad = 0;
  bool covered = false;  // along an edge (within alpha_min / 2): not cast
  ProbeState state = ProbeState::kOther;
  SupportQuery::ProbeWhy why;  // for an open probe
};

class TopologicalFrontiers {
 public:
  explicit TopologicalFrontiers(const GraphOptions& opt = {});

  // `changed`: regions that changed (frontier nodes near them are re-evaluated: unknown space
  // only ever becomes known, so a non-frontier node stays one unless its edges change or
  // something is removed); `opened`: regions that lost occupied voxels (every node near them
  // is re-evaluated: a probe or a sample may see through now). Nodes the graph touched are
  // always re-evaluated. Pass the same boxes twice when the kind of change is unknown.
  FrontierUpdateStats update(ReachableGraph& g, const map::MapView& view,
                             const Eigen::Vector3f& robot_m, std::span<const Aabb> changed,
                             std::span<const Aabb> opened);
  // Kind of change unknown (e.g. plain scan bounds): every node near `changed` is re-evaluated.
  FrontierUpdateStats update(ReachableGraph& g, const map::MapView& view,
                             const Eigen::Vector3f& robot_m, std::span<const Aabb> changed) {
    return update(g, view, robot_m, changed, changed);
  }
  // Evaluates one node now (also used by tests): writes rho, open_dirs and the flags.
  void evaluate(ReachableGraph& g, const map::MapView& view, NodeId i);
  // Every C_exp probe of node i as evaluate() casts it now (the graph is not changed).
  std::vector<ProbeExplanation> explain(const ReachableGraph& g, const map::MapView& view,
                                        NodeId i);
  bool idle() const { return queue_.empty(); }

 private:
  float missing_surface_ratio(SupportQuery& q, const GraphNode& n, int* samples);  // Eq. 5
  // *passages (optional): passage_probes() of the probes cast (GraphOptions::passage_frontiers).
  int open_directions(SupportQuery& q, const ReachableGraph& g, NodeId i, int* up,
                      int* leads = nullptr, int* passages = nullptr,
                      std::vector<ProbeExplanation>* explained = nullptr);
  bool near_reach_boundary(SupportQuery& q, const GraphNode& n);
  void evaluate(ReachableGraph& g, SupportQuery& q, NodeId i);
  void evaluate_flags(ReachableGraph& g, SupportQuery& q, NodeId i);

  GraphOptions opt_;
  std::vector<Eigen::Vector2f> disc_;  // Omega_i sample offsets (unit disc, sunflower pattern)
  std::deque<NodeId> queue_;
  std::vector<uint8_t> queued_;
  std::vector<NodeId> scratch_;
  std::vector<uint8_t> cls_;
  std::vector<ProbeState> probe_state_;  // open_directions: per probe (scratch)
  std::vector<Aabb> boxes_, opened_;
};

}  // namespace storey::core::graph
