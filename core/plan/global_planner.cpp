#include "core/plan/global_planner.hpp"

#include <algorithm>

namespace storey::core::plan {

GlobalPlan GlobalPlanner::solve(const HybridGraph& hg, uint32_t robot_node) {
  GlobalPlan out;
  const SearchGraph& g = hg.search_graph();
  if (robot_node >= g.num_nodes()) return out;
  auto real = [&](uint32_t e, uint32_t, uint32_t) { return hg.csr_edge_real(e); };
  auto centre_of = [&](int32_t id) {
    for (const HybridZone& z : hg.zones())
      if (z.id == id) return z.centre;
    return kNoNode;
  };
  // Drop zones the robot cannot reach at all (row 0 decides).
  targets_.clear();
  for (int32_t id : zone_ids_) targets_.push_back(centre_of(id));
  row_.assign(targets_.size(), kUnreachable);
  auto two_stage_row = [&](uint32_t from, std::span<double> out_row) {
    search_.costs_from(g, from, targets_, out_row, real);
    bool missing = false;
    for (double c : out_row) missing = missing || c == kUnreachable;
    if (!missing) return false;
    hybrid_row_.resize(targets_.size());
    search_.costs_from(g, from, targets_, hybrid_row_, AllEdges{});
    for (size_t i = 0; i < out_row.size(); ++i)
      if (out_row[i] == kUnreachable) out_row[i] = hybrid_row_[i];
    return true;
  };
  out.hybrid_rows += two_stage_row(robot_node, row_);
  for (double c : row_) out.unreachable += c == kUnreachable;
  // The max_zones_ nearest reachable zones (ties: list order, i.e. zone id) enter the TSP; kept
  // in list order so the matrix does not depend on the ranking.
  by_cost_.clear();
  for (size_t i = 0; i < targets_.size(); ++i)
    if (row_[i] != kUnreachable) by_cost_.push_back(i);
  if (by_cost_.size() > size_t(max_zones_)) {
    std::stable_sort(by_cost_.begin(), by_cost_.end(),
                     [&](size_t a, size_t b) { return row_[a] < row_[b]; });
    out.deferred = int(by_cost_.size()) - max_zones_;
    by_cost_.resize(size_t(max_zones_));
    std::sort(by_cost_.begin(), by_cost_.end());
  }
  const size_t k = by_cost_.size();
  for (size_t j = 0; j < k; ++j) {
    const size_t i = by_cost_[j];
    zone_ids_[j] = zone_ids_[i];
    targets_[j] = targets_[i];
    row_[j] = row_[i];
  }
  zone_ids_.resize(k);
  targets_.resize(k);
  row_.resize(k);
  const int n = int(k) + 1;  // index 0 = robot
  costs_.assign(size_t(n) * size_t(n), 0.0);
  std::vector<double> r(k);
  for (int i = 0; i < n; ++i) {
    if (i == 0) {
      r = row_;  // the robot's row is the one computed above
    } else {
      out.hybrid_rows += two_stage_row(targets_[size_t(i - 1)], r);
    }
    for (size_t j = 0; j < k; ++j) costs_[size_t(i) * size_t(n) + j + 1] = r[j];
    costs_[size_t(i) * size_t(n)] = kUnreachable;  // open tour: never return to the robot
  }
  out.ok = true;
  if (k == 0) return out;
  const TspResult t = tsp_.solve(CostMatrix{n, costs_}, 0, -1);
  if (t.status != TspStatus::kOk) {
    out.ok = false;
    return out;
  }
  out.cost = t.cost;
  for (size_t i = 1; i < t.order.size(); ++i)
    out.zone_order.push_back(zone_ids_[size_t(t.order[i] - 1)]);
  return out;
}

Approach GlobalPlanner::approach(const HybridGraph& hg, uint32_t robot_node, uint32_t goal) {
  Approach a;
  const SearchGraph& g = hg.search_graph();
  if (robot_node >= g.num_nodes() || goal >= g.num_nodes()) return a;
  const TwoStageResult r = search_.two_stage_astar(
      g, robot_node, goal, [&](uint32_t e, uint32_t, uint32_t) { return hg.csr_edge_real(e); });
  if (!r.found) return a;
  a.ok = true;
  a.used_hybrid = r.used_hybrid;
  a.path = r.nodes;
  a.real_prefix = real_prefix_length(std::span<const uint32_t>(a.path),
                                     [&](uint32_t u) { return hg.node_real(u); });
  if (a.real_prefix > 0) a.goal_m = hg.nodes()[a.path[a.real_prefix - 1]].p_m;
  return a;
}

}  // namespace storey::core::plan
