#pragma once
// What the map task publishes each cycle (immutable once published): the world model every other
// task reads through an rt::Snapshot. Split from autonomy.hpp so that the exploration policies
// (exploration_policy.hpp) can read it without the task table.
#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

#include "core/graph/frontier_clusters.hpp"
#include "core/graph/reachable_graph.hpp"
#include "core/graph/viewpoint_generator.hpp"
#include "core/map/traversability_map.hpp"

namespace storey::firmware {

struct WorldModel {
  uint64_t cycle = 0;
  double stamp_s = 0;
  std::shared_ptr<const core::map::MapSnapshot> map;
  core::graph::ReachableGraph graph;
  std::vector<core::graph::FrontierCluster> clusters;
  std::vector<core::graph::ClusterViewpoints> viewpoints;
  bool settled = false;  // graph and frontier work queues empty (nothing carried over)
  uint32_t frontier_nodes = 0;
  uint64_t scans = 0;  // scans inserted so far
  // Map regions changed by the scans of each map cycle (cycle, box), for every cycle after the
  // last one the plan task acknowledged (Autonomy: plan_seen_cycle_), so the planner can re-check
  // only what changed since its previous call (ExplorationInput::changed_regions).
  std::vector<std::pair<uint64_t, core::graph::Aabb>> changes;
};

}  // namespace storey::firmware
