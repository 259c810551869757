#include "tools/sim/exploration_diagnostics.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <unordered_set>

#include "core/graph/topological_frontiers.hpp"

namespace storey::tools::sim {

namespace {

std::string f(const char* fmt, double a, double b = 0, double c = 0) {
  char buf[128];
  std::snprintf(buf, sizeof buf, fmt, a, b, c);
  return buf;
}

// What the map holds where a ground-truth traversable voxel is not covered.
enum Gap : int {
  kUnknown = 0,      // nothing observed in the column at that level
  kSeenFree,         // the voxel above the ground is observed free, but no ground return
  kUnobsFew,         // occupied support with fewer than N_min points (S_unobs, Eq. 3)
  kUnobsDegenerate,  // >= N_min points but collinear neighbourhood (a single scan line)
  kUntravNotTop,
  kUntravCost,
  kUntravCollision,
  kUntravFall,
  kOtherHeight,  // traversable in the column, but more than one voxel off the truth
  kGapCount
};
const char* kGapNames[kGapCount] = {
    "never observed (unknown)",
    "observed free above, no ground return",
    "under-observed support: N(v) < N_min",
    "under-observed support: collinear (one scan line)",
    "untraversable: not a top surface",
    "untraversable: cost > tau_c",
    "untraversable: R_col",
    "untraversable: R_fall",
    "traversable at another height (> 1 voxel off)",
};

}  // namespace

std::string exploration_diagnostics(const firmware::Autonomy& autonomy, const GroundTruth& gt,
                                    const Eigen::Vector3d& robot_m) {
  std::string out = "# Exploration diagnostics\n\n";
  const firmware::ExplorationStatus st = autonomy.status();
  out += "Final state: " + std::string(firmware::to_string(st.state)) +
         ", last plan: " + core::plan::to_string(st.last_plan) + f(", at %.1f s", st.stamp_s) +
         "\n\n";
  const auto& planner = autonomy.planner_for_record();

  // ---- 1. Frontier clusters left.
  const auto w = autonomy.world();
  if (w) {
    const auto& g = w->graph;
    out += "## Frontier clusters left: " + std::to_string(w->clusters.size()) + " (" +
           std::to_string(w->frontier_nodes) + " frontier nodes; graph " +
           std::to_string(g.node_count()) + " nodes" + (w->settled ? ", settled" : ", busy") +
           ")\n\n";
    out +=
        "| cluster | node | x, y, z [m] | state | C_sur (rho) | C_exp (open) | to robot [m] | "
        "set aside |\n|---|---|---|---|---|---|---|---|\n";
    const Eigen::Vector3f r = robot_m.cast<float>();
    for (const auto& c : w->clusters)
      for (core::graph::NodeId id : c.nodes) {
        const auto& n = g.node(id);
        const core::plan::SetAsideEntry* e = planner.set_aside_at(n.p_m);
        out += "| " + std::to_string(c.id) + " | " + std::to_string(id) + " | " +
               f("%.2f, %.2f, %.2f", n.p_m.x(), n.p_m.y(), n.p_m.z()) + " | " +
               (n.state == core::graph::ElementState::kConfirmed ? "conf" : "tent") + " | " +
               (n.c_sur ? "yes" : "no") + f(" (%.2f)", n.rho) + " | " + (n.c_exp ? "yes" : "no") +
               " (" + std::to_string(n.open_dirs) + ") | " + f("%.1f", (n.p_m - r).norm()) + " | " +
               (e ? std::string(core::plan::to_string(e->reason)) + f(" at %.1f s", e->t_s) +
                        (e->hit_m.allFinite() ? f(" (body hit %.2f, %.2f, %.2f)", e->hit_m.x(),
                                                  e->hit_m.y(), e->hit_m.z())
                                              : std::string())
                  : std::string("-")) +
               " |\n";
      }
    out += "\n";
    // Why each C_exp node is open, probe by probe (a frontier that no view resolves shows here).
    core::graph::TopologicalFrontiers tf(autonomy.params().graph);
    const core::map::MapView view = autonomy.map_for_record().view();
    std::string probes;
    for (const auto& c : w->clusters)
      for (core::graph::NodeId id : c.nodes) {
        if (!g.node(id).c_exp) continue;
        std::string row;
        for (const auto& p : tf.explain(g, view, id)) {
          if (p.state != core::graph::ProbeState::kOpen) continue;
          using By = core::graph::SupportQuery::OpenBy;
          const char* by = p.why.by == By::kUnknownRun            ? "unknown from"
                           : p.why.by == By::kUnobservedStep      ? "under-observed step at"
                           : p.why.by == By::kUnknownOverObstacle ? "unknown over an obstacle at"
                                                                  : "open";
          row += f("; %.0f deg: ", p.theta_rad * 180 / M_PI) + by +
                 f(" %.2f, %.2f, %.2f", p.why.at_m.x(), p.why.at_m.y(), p.why.at_m.z());
        }
        if (!row.empty()) probes += "- node " + std::to_string(id) + row.substr(1) + "\n";
      }
    if (!probes.empty())
      out +=
          "Open C_exp probes of the frontier nodes (direction: the unknown that opens it, "
          "at the probe's height):\n\n" +
          probes + "\n";
  }
  std::map<std::string, int> reasons;
  for (const auto& e : planner.set_aside()) ++reasons[core::plan::to_string(e.reason)];
  // Entries expire when the map near them changes: the list is what is set aside now.
  out += "Set-aside frontier nodes at the end: " + std::to_string(planner.set_aside().size());
  for (const auto& [k, v] : reasons) out += ", " + k + " " + std::to_string(v);
  out += " (" + std::to_string(planner.set_aside().size() + planner.set_aside_expired()) +
         " over the run, " + std::to_string(planner.set_aside_expired()) +
         " expired when the map near them changed)\n";
  out +=
      "No-progress events (stood still with a target for plan.no_progress_s; target set aside, "
      "stepped away): " +
      std::to_string(planner.no_progress_events()) + "\n\n";

  // ---- 2. Coverage gaps: what the map holds at uncovered ground-truth traversable voxels.
  const auto& map = autonomy.map_for_record();
  const core::map::MapView view = map.view();
  std::unordered_set<VoxelKey, VoxelKeyHash> trav;
  view.for_each_occupied([&](const core::map::VoxelKey& k, const core::map::Cell& c, auto*) {
    if (c.state == core::map::TravState::kTraversable) trav.insert({k.x, k.y, k.z});
  });
  const size_t nf = gt.floors().size();
  std::vector<std::array<size_t, kGapCount>> gaps(nf);
  std::vector<size_t> total(nf, 0), covered(nf, 0), edge(nf, 0);
  for (auto& a : gaps) a.fill(0);
  std::map<std::pair<int, std::pair<int, int>>, std::array<size_t, kGapCount>> cells;
  const double res = gt.resolution();
  for (const VoxelKey& k : gt.reachable_voxels()) {
    const int fl = gt.floor_of(k);
    if (fl < 0) continue;
    ++total[fl];
    if (trav.count(k) || trav.count({k.x, k.y, k.z - 1}) || trav.count({k.x, k.y, k.z + 1})) {
      ++covered[fl];
      continue;
    }
    bool at_edge = false;
    for (int d = 0; d < 4; ++d) {
      const VoxelKey nb{k.x + (d == 0) - (d == 1), k.y + (d == 2) - (d == 3), k.z};
      at_edge = at_edge || !(gt.reachable(nb) || gt.reachable({nb.x, nb.y, nb.z - 1}) ||
                             gt.reachable({nb.x, nb.y, nb.z + 1}));
    }
    edge[fl] += at_edge;
    Gap gap = kUnknown;
    bool found = false;
    for (int dz = 1; dz >= -1 && !found; --dz) {  // top-down: the support voxel
      const core::map::VoxelKey m{k.x, k.y, k.z + dz};
      if (view.occupancy(m) != core::map::Occupancy::kOccupied) continue;
      found = true;
      const uint32_t n = view.point_count(m);
      switch (view.state(m)) {
        case core::map::TravState::kUnobserved:
          gap = n < uint32_t(map.options().n_min) ? kUnobsFew : kUnobsDegenerate;
          break;
        case core::map::TravState::kUntraversable: {
          const core::map::VoxelStats* s = core::map::BlockReader(view.store()).stats(m);
          const uint8_t r = s ? s->reasons : 0;
          gap = (r & core::map::VoxelStats::kReasonNotTop)      ? kUntravNotTop
                : (r & core::map::VoxelStats::kReasonCollision) ? kUntravCollision
                : (r & core::map::VoxelStats::kReasonFall)      ? kUntravFall
                                                                : kUntravCost;
          break;
        }
        default:
          gap = kUnobsFew;
      }
    }
    if (!found) {
      bool other = false;
      for (int dz = -4; dz <= 4 && !other; ++dz) other = trav.count({k.x, k.y, k.z + dz}) > 0;
      if (other)
        gap = kOtherHeight;
      else
        gap = view.occupancy(core::map::VoxelKey{k.x, k.y, k.z + 1}) == core::map::Occupancy::kFree
                  ? kSeenFree
                  : kUnknown;
    }
    ++gaps[fl][gap];
    auto& cell = cells[{fl, {int(std::floor(k.x * res)), int(std::floor(k.y * res))}}];
    ++cell[gap];
  }
  out += "## Ground-truth traversable voxels not covered, by what the map holds there\n\n";
  out += "| floor | truth voxels | covered | uncovered | at the edge of the truth |";
  for (int g = 0; g < kGapCount; ++g) out.append(" ").append(kGapNames[g]).append(" |");
  out += "\n|---|---|---|---|---|";
  for (int g = 0; g < kGapCount; ++g) out += "---|";
  out += "\n";
  for (size_t fl = 0; fl < nf; ++fl) {
    out += "| " + std::to_string(fl) + " | " + std::to_string(total[fl]) + " | " +
           f("%.1f %%", total[fl] ? 100.0 * double(covered[fl]) / double(total[fl]) : 0.0) + " | " +
           std::to_string(total[fl] - covered[fl]) + " | " + std::to_string(edge[fl]) + " |";
    for (int g = 0; g < kGapCount; ++g)
      out.append(" ").append(std::to_string(gaps[fl][g])).append(" |");
    out += "\n";
  }
  // The 1 m x 1 m cells with the most uncovered voxels (where the holes are).
  std::vector<std::pair<size_t, decltype(cells)::const_iterator>> worst;
  for (auto it = cells.cbegin(); it != cells.cend(); ++it) {
    size_t n = 0;
    for (size_t v : it->second) n += v;
    worst.push_back({n, it});
  }
  std::sort(worst.begin(), worst.end(),
            [](const auto& a, const auto& b) { return a.first > b.first; });
  out += "\nWorst 1 m cells (floor, x, y: uncovered voxels of 100, main cause):\n\n";
  for (size_t i = 0; i < worst.size() && i < 15; ++i) {
    const auto& [key, arr] = *worst[i].second;
    const int main = int(std::max_element(arr.begin(), arr.end()) - arr.begin());
    out += "- floor " + std::to_string(key.first) + " (" + std::to_string(key.second.first) + ", " +
           std::to_string(key.second.second) + "): " + std::to_string(worst[i].first) + ", " +
           kGapNames[main] + "\n";
  }
  return out;
}

}  // namespace storey::tools::sim
