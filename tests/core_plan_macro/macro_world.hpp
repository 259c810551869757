#pragma once
// Box worlds, a synthetic range scanner and a map + graph harness for the macro-layer tests
// (the same idea as tests/core_graph/graph_world.hpp, kept here so the folders evolve freely).
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

namespace storey::test::macro {

struct Box {
  Eigen::Vector3f lo, hi;
};

struct World {
  std::vector<Box> boxes;
  void add(Eigen::Vector3f lo, Eigen::Vector3f hi) { boxes.push_back({lo, hi}); }
  // Stairs rising along +x from (x0, y0..y1, z0): n solid steps of rise/tread.
  void stairs(float x0, float y0, float y1, float z0, int n, float rise, float tread) {
    for (int i = 0; i < n; ++i)
      add({x0 + i * tread, y0, z0 - 0.2f}, {x0 + (i + 1) * tread, y1, z0 + (i + 1) * rise});
  }
  float cast(const Eigen::Vector3f& o, const Eigen::Vector3f& d, float max_t) const {
    float best = max_t;
    for (const Box& b : boxes) {
      float t0 = 0, t1 = best;
      bool miss = false;
      for (int a = 0; a < 3 && !miss; ++a) {
        if (std::abs(d[a]) < 1e-12f) {
          if (o[a] < b.lo[a] || o[a] > b.hi[a]) miss = true;
          continue;
        }
        float ta = (b.lo[a] - o[a]) / d[a], tb = (b.hi[a] - o[a]) / d[a];
        if (ta > tb) std::swap(ta, tb);
        t0 = std::max(t0, ta);
        t1 = std::min(t1, tb);
        if (t0 > t1) miss = true;
      }
      if (!miss && t0 > 1e-6f && t0 < best) best = t0;
    }
    return best < max_t ? best : std::numeric_limits<float>::infinity();
  }
};

inline std::vector<Eigen::Vector3f> scan(const World& w, const Eigen::Vector3f& o, int n,
                                         uint32_t seed, float max_range = 12.f) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> az(0.f, 2.f * float(M_PI)), el(-1.2f, 1.0f);
  std::normal_distribution<float> noise(0.f, 0.003f);
  std::vector<Eigen::Vector3f> pts;
  pts.reserve(size_t(n));
  for (int i = 0; i < n; ++i) {
    const float a = az(rng), e = el(rng);
    const Eigen::Vector3f d(std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e));
    const float t = w.cast(o, d, max_range);
    if (std::isfinite(t)) pts.push_back(o + d * (t + noise(rng)));
  }
  return pts;
}

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

  // One scan from 0.5 m above the feet, then graph/frontier cycles until idle.
  void observe(const World& w, const Eigen::Vector3f& foot_m, int rays, uint32_t seed) {
    const Eigen::Vector3f sensor = foot_m + Eigen::Vector3f(0, 0, 0.5f);
    const auto pts = scan(w, sensor, rays, seed);
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
