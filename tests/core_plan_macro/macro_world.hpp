#pragma once
// A map + graph + frontiers + clusters + viewpoints harness for the macro-layer tests, over the
// box worlds and synthetic scanner of tests/core_graph/graph_world.hpp.
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include <Eigen/Geometry>

#include "core/graph/frontier_clusters.hpp"
#include "core/graph/reachable_graph.hpp"
#include "core/graph/topological_frontiers.hpp"
#include "core/graph/viewpoint_generator.hpp"
#include "core/map/traversability_map.hpp"
#include "tests/core_graph/graph_world.hpp"

namespace storey::test::macro {

// The box world and the synthetic scanner are the graph tests' (one scanner for both folders).
using graph::Box;
using graph::scan;
using graph::World;

// Map + graph + frontiers + clusters + viewpoints, as the firmware's map task runs them.
struct Harness {
  core::map::TraversabilityMap map;
  core::graph::ReachableGraph graph;
  core::graph::TopologicalFrontiers frontiers;
  core::graph::FrontierClusters clusters;
  core::graph::ViewpointGenerator viewpoints;
  std::mt19937_64 rng;
  Eigen::Vector3f foot = Eigen::Vector3f::Zero();

  explicit Harness(const core::graph::GraphOptions& o = {}, uint64_t seed = 1)
      : graph(o), frontiers(o), clusters(o), viewpoints(o), rng(seed) {}

  // One scan from 0.5 m above the feet (rays between el_min and el_max [rad] of elevation), then
  // graph/frontier cycles until idle.
  void observe(const World& w, const Eigen::Vector3f& foot_m, int rays, uint32_t seed,
               float el_min = -1.2f, float el_max = 1.0f) {
    const Eigen::Vector3f sensor = foot_m + Eigen::Vector3f(0, 0, 0.5f);
    insert(sensor, scan(w, sensor, rays, seed, 12.f, el_min, el_max), foot_m);
  }
  // The returns pts seen from sensor (the robot's feet at foot_m), then graph/frontier cycles.
  void insert(const Eigen::Vector3f& sensor, const std::vector<Eigen::Vector3f>& pts,
              const Eigen::Vector3f& foot_m) {
    map.insert_scan(sensor, pts);
    map.update_traversability();
    map.update_reachable(foot_m);
    foot = foot_m;
    const core::graph::Aabb box = core::graph::scan_bounds(sensor, pts);
    graph.update(map.view(), foot, std::span(&box, 1), rng);
    frontiers.update(graph, map.view(), foot, std::span(&box, 1));
    for (int i = 0; i < 200 && !(graph.idle() && frontiers.idle()); ++i) {
      graph.update(map.view(), foot, {}, rng);
      frontiers.update(graph, map.view(), foot, {});
    }
    clusters.update(graph);
    viewpoints.update(graph, map.view(), clusters.clusters());
  }
};

}  // namespace storey::test::macro
