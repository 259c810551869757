#pragma once
// Global guidance on the hybrid graph (paper Sec. IV-C): an open-loop TSP from the robot over
// the uncompleted zones Z+ = {Z_k | sigma(Z_k) != C}, travel costs D_ij between the centres by
// the two-stage search (real elements only; if that finds no path, the whole hybrid graph).
// Rows of D come from one Dijkstra per centre with the real-only filter, plus one over the
// hybrid graph for the centres the first could not reach (same result as a two-stage A* per
// pair, 2 searches per row instead of 2 per pair). Zones no route reaches are left out and
// reported. Bounded work: only the max_tsp_zones zones nearest the robot (two-stage cost) enter
// the TSP, the rest wait for a later cycle (as the local layer's PlanOptions::tsp_max_clusters):
// the local layer only serves the first guidance_zones of the sequence, and a building-size prior
// holds ~100 zones (one row = one Dijkstra over the whole hybrid graph). Execution toward a zone
// follows only the real prefix of its path (approach()).
#include <algorithm>
#include <cstdint>
#include <span>
#include <vector>

#include <Eigen/Core>

#include "core/plan/graph_search.hpp"
#include "core/plan/hybrid_graph.hpp"
#include "core/plan/tsp.hpp"

namespace storey::core::plan {

struct GlobalPlan {
  bool ok = false;
  std::vector<int32_t> zone_order;  // zone ids, visiting order (robot first, not listed)
  double cost = 0;                  // tour cost [m]
  int unreachable = 0;              // uncompleted zones no route reaches (left out)
  int hybrid_rows = 0;              // rows that needed the hybrid stage
  int deferred = 0;                 // reachable zones beyond max_tsp_zones (not in zone_order)
};

struct Approach {
  bool ok = false;
  bool used_hybrid = false;
  std::vector<uint32_t> path;  // compiled node indices, robot ... zone centre
  size_t real_prefix = 0;      // leading real nodes of `path` (Sec. IV-C: only these are driven)
  Eigen::Vector3d goal_m = Eigen::Vector3d::Zero();  // last node of the real prefix
};

class GlobalPlanner {
 public:
  // max_tsp_zones: zones entering the TSP (nearest first), >= 1.
  explicit GlobalPlanner(const TspOptions& tsp = {}, int max_tsp_zones = kDefaultMaxTspZones)
      : tsp_(tsp), max_zones_(std::max(1, max_tsp_zones)) {}
  static constexpr int kDefaultMaxTspZones = 16;
  // excluded(zone id) -> true: leave the zone out (e.g. the robot could not approach it).
  template <class Excluded>
  GlobalPlan plan(const HybridGraph& hg, uint32_t robot_node, Excluded&& excluded);
  // Two-stage A* from the robot to a node and the real prefix of the path.
  Approach approach(const HybridGraph& hg, uint32_t robot_node, uint32_t goal);

 private:
  GlobalPlan solve(const HybridGraph& hg, uint32_t robot_node);
  TspSolver tsp_;
  int max_zones_;
  GraphSearch search_;
  std::vector<int32_t> zone_ids_;
  std::vector<uint32_t> targets_;
  std::vector<double> costs_, row_, hybrid_row_;
  std::vector<size_t> by_cost_;
};

template <class Excluded>
GlobalPlan GlobalPlanner::plan(const HybridGraph& hg, uint32_t robot_node, Excluded&& excluded) {
  zone_ids_.clear();
  for (const HybridZone& z : hg.zones())
    if (z.state != ZoneState::kCompleted && !excluded(z.id)) zone_ids_.push_back(z.id);
  return solve(hg, robot_node);
}

}  // namespace storey::core::plan
