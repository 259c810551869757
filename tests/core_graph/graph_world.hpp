#pragma once
// Analytic box worlds and a synthetic range scanner for the graph tests (same idea as
// tests/core_map/synthetic_world.hpp, kept separate so the two test folders evolve freely),
// plus a small harness that runs map + graph cycles like the firmware's map task.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <random>
#include <vector>

#include <Eigen/Geometry>

#include "core/graph/reachable_graph.hpp"
#include "core/graph/topological_frontiers.hpp"
#include "core/map/traversability_map.hpp"

namespace storey::test::graph {

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

// n rays uniform in azimuth, elevation uniform in [el_min, el_max] [rad], up to max_range.
inline std::vector<Eigen::Vector3f> scan(const World& w, const Eigen::Vector3f& o, int n,
                                         uint32_t seed, float max_range = 12.f,
                                         float el_min = -1.2f, float el_max = 1.0f) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> az(0.f, 2.f * float(M_PI)), el(el_min, el_max);
  std::normal_distribution<float> noise(0.f, 0.003f);
  std::vector<Eigen::Vector3f> pts;
  pts.reserve(n);
  for (int i = 0; i < n; ++i) {
    const float a = az(rng), e = el(rng);
    const Eigen::Vector3f d(std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e));
    const float t = w.cast(o, d, max_range);
    if (std::isfinite(t)) pts.push_back(o + d * (t + noise(rng)));
  }
  return pts;
}

// Map + graph cycle as the map task runs it.
struct Harness {
  core::map::TraversabilityMap map;
  core::graph::ReachableGraph graph;
  core::graph::TopologicalFrontiers frontiers;
  std::mt19937_64 rng;
  Eigen::Vector3f foot = Eigen::Vector3f::Zero();
  core::graph::GraphUpdateStats last;
  int settle_cycles = 200;  // graph cycles observe() runs after the scan's (0: just the one)

  explicit Harness(const core::graph::GraphOptions& o = {}, uint64_t seed = 1)
      : graph(o), frontiers(o), rng(seed) {}

  // Scan from `sensor`, robot standing with its feet at `foot_m`; then run graph cycles until
  // the graph is idle (tests want the converged graph, not the per-cycle budget).
  void observe(const World& w, const Eigen::Vector3f& sensor, const Eigen::Vector3f& foot_m,
               int rays, uint32_t seed, float max_range = 12.f) {
    const auto pts = scan(w, sensor, rays, seed, max_range);
    map.insert_scan(sensor, pts);
    map.update_traversability();
    map.update_reachable(foot_m);
    foot = foot_m;
    const core::graph::Aabb box = core::graph::scan_bounds(sensor, pts);
    last = graph.update(map.view(), foot, std::span(&box, 1), rng);
    frontiers.update(graph, map.view(), foot, std::span(&box, 1), std::span(&box, 1));
    for (int r = 0; r < int(core::graph::Reject::kCount); ++r) rejects[r] += last.rejects[r];
    settle(settle_cycles);
    if (getenv("STOREY_DEBUG"))
      printf(
          "observe at %.2f %.2f %.2f: nodes %zu edges %zu reach %lu | pruned %u disc %u "
          "root %d iso %d reval %u exp %u | rejects ok %u nosup %u untrav %u col %u fall %u step "
          "%u slope %u gap "
          "%u notreach %u\n",
          sensor.x(), sensor.y(), sensor.z(), graph.node_count(), graph.edge_count(),
          (unsigned long)map.reachable_voxels(), last.nodes_pruned, last.disconnected,
          int(last.has_root), int(last.root_isolated), last.revalidated, last.expanded, rejects[0],
          rejects[1], rejects[2], rejects[3], rejects[4], rejects[5], rejects[6], rejects[7],
          rejects[8]);
  }
  void settle(int max_cycles = 200) {
    for (int i = 0; i < max_cycles && !(graph.idle() && frontiers.idle()); ++i) {
      const auto st = graph.update(map.view(), foot, {}, rng);
      frontiers.update(graph, map.view(), foot, {}, {});
      for (int r = 0; r < int(core::graph::Reject::kCount); ++r) rejects[r] += st.rejects[r];
      last.nodes_pruned += st.nodes_pruned;
      last.disconnected += st.disconnected;
    }
  }
  uint32_t rejects[int(core::graph::Reject::kCount)] = {};
};

}  // namespace storey::test::graph
