// Graph + frontier + clustering update per map cycle at building scale (DESIGN.md §6: p99 <= 10
// ms with >= 5,000 nodes), and viewpoint scoring per cluster (paper Sec. III-B, III-C).
//
// The building: one 78 x 48 m storey of 13 x 8 rooms (6 m, 0.1 m walls, a 1 m door in every
// wall), mapped once by synthetic scans from every room centre; the graph is grown to
// convergence before timing (~8,000 nodes). Two cycle benchmarks:
//  graph/cycle_moving_obstacle: the robot walks through a row of rooms (0.1 m per 10 Hz cycle)
//    with a person-sized box walking ahead of it; every cycle inserts a scan (floor around the
//    robot and the box, untimed: the map's cost), then times MapChangeDetector::detect on the
//    scan bounds + ReachableGraph::update + TopologicalFrontiers::update +
//    FrontierClusters::update.
//  graph/cycle_region/<m>: worst case without change detection: the whole +-m box around the
//    robot is reported changed every cycle; the per-cycle budgets bound the work.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <memory>
#include <vector>

#include <benchmark/benchmark.h>

#include "core/graph/frontier_clusters.hpp"
#include "core/graph/map_change_detector.hpp"
#include "core/graph/reachable_graph.hpp"
#include "core/graph/topological_frontiers.hpp"
#include "core/graph/viewpoint_generator.hpp"
#include "core/map/traversability_map.hpp"
#include "tests/core_graph/graph_world.hpp"

namespace {

using namespace storey::core;
using Eigen::Vector3f;

constexpr int kRoomsX = 13, kRoomsY = 8;
constexpr float kRoom = 6.0f, kWallHalf = 0.05f, kDoorHalf = 0.5f, kHeight = 2.5f;

bool in_wall(float x, float y) {
  const float fx = std::fmod(x, kRoom), fy = std::fmod(y, kRoom);
  const bool wx = fx < kWallHalf || fx > kRoom - kWallHalf;  // wall along y at x = k * room
  const bool wy = fy < kWallHalf || fy > kRoom - kWallHalf;
  const bool outer = x < kWallHalf || y < kWallHalf || x > kRoomsX * kRoom - kWallHalf ||
                     y > kRoomsY * kRoom - kWallHalf;
  const bool door_x = std::abs(fy - kRoom / 2) < kDoorHalf;  // door in a wall along y
  const bool door_y = std::abs(fx - kRoom / 2) < kDoorHalf;
  if (outer) return true;
  return (wx && !door_x) || (wy && !door_y);
}

// The building as boxes (floor slab, walls split around their doors).
storey::test::graph::World building_world() {
  storey::test::graph::World w;
  const float X = kRoomsX * kRoom, Y = kRoomsY * kRoom;
  w.add({-0.2f, -0.2f, -0.3f}, {X + 0.2f, Y + 0.2f, 0.0f});
  for (int i = 0; i <= kRoomsX; ++i)  // walls along y at x = i * room
    for (int j = 0; j < kRoomsY; ++j) {
      const float x = i * kRoom, y0 = j * kRoom, yc = y0 + kRoom / 2;
      const bool outer = i == 0 || i == kRoomsX;
      if (outer) {
        w.add({x - kWallHalf, y0, 0}, {x + kWallHalf, y0 + kRoom, kHeight});
      } else {
        w.add({x - kWallHalf, y0, 0}, {x + kWallHalf, yc - kDoorHalf, kHeight});
        w.add({x - kWallHalf, yc + kDoorHalf, 0}, {x + kWallHalf, y0 + kRoom, kHeight});
      }
    }
  for (int j = 0; j <= kRoomsY; ++j)  // walls along x at y = j * room
    for (int i = 0; i < kRoomsX; ++i) {
      const float y = j * kRoom, x0 = i * kRoom, xc = x0 + kRoom / 2;
      const bool outer = j == 0 || j == kRoomsY;
      if (outer) {
        w.add({x0, y - kWallHalf, 0}, {x0 + kRoom, y + kWallHalf, kHeight});
      } else {
        w.add({x0, y - kWallHalf, 0}, {xc - kDoorHalf, y + kWallHalf, kHeight});
        w.add({xc + kDoorHalf, y - kWallHalf, 0}, {x0 + kRoom, y + kWallHalf, kHeight});
      }
    }
  return w;
}

// The boxes near a point (ray casting against ~10 boxes instead of ~400).
storey::test::graph::World local_world(const storey::test::graph::World& w, const Vector3f& c,
                                       float r) {
  storey::test::graph::World out;
  for (const auto& b : w.boxes)
    if (b.lo.x() <= c.x() + r && b.hi.x() >= c.x() - r && b.lo.y() <= c.y() + r &&
        b.hi.y() >= c.y() - r)
      out.boxes.push_back(b);
  return out;
}

struct Building {
  map::TraversabilityMap map;
  graph::GraphOptions opt;
  std::unique_ptr<graph::ReachableGraph> graph;
  std::unique_ptr<graph::TopologicalFrontiers> frontiers;
  std::unique_ptr<graph::FrontierClusters> clusters;
  std::mt19937_64 rng{1};
  Vector3f foot{kRoom / 2, kRoom / 2, 0};

  Building() {
    // A LiDAR-like scan (300k rays, 0.5 m above the floor, 8 m range) from every room centre.
    const storey::test::graph::World world = building_world();
    for (int rx = 0; rx < kRoomsX; ++rx)
      for (int ry = 0; ry < kRoomsY; ++ry) {
        const Vector3f o(rx * kRoom + kRoom / 2, ry * kRoom + kRoom / 2, 0.5f);
        const auto pts = storey::test::graph::scan(local_world(world, o, 9.0f), o, 300000,
                                                   uint32_t(rx * 100 + ry), 8.0f);
        map.insert_scan(o, pts);
      }
    map.update_traversability();
    map.update_reachable(foot);
    graph = std::make_unique<graph::ReachableGraph>(opt);
    frontiers = std::make_unique<graph::TopologicalFrontiers>(opt);
    clusters = std::make_unique<graph::FrontierClusters>(opt);
    // Grow to convergence: the robot visits every room once.
    for (int rx = 0; rx < kRoomsX; ++rx)
      for (int ry = 0; ry < kRoomsY; ++ry) {
        foot = Vector3f(rx * kRoom + kRoom / 2, ry * kRoom + kRoom / 2, 0);
        for (int i = 0; i < 50 && (i == 0 || !graph->idle()); ++i)
          graph->update(map.view(), foot, {}, rng);
      }
    for (int i = 0; i < 200 && !(graph->idle() && frontiers->idle()); ++i) {
      graph->update(map.view(), foot, {}, rng);
      frontiers->update(*graph, map.view(), foot, {}, {});
    }
    graph->touch_all();
    for (int i = 0; i < 200 && !(graph->idle() && frontiers->idle()); ++i) {
      graph->update(map.view(), foot, {}, rng);
      frontiers->update(*graph, map.view(), foot, {}, {});
    }
    clusters->update(*graph);
  }
};

Building& building() {
  static Building b;
  return b;
}

// Per-cycle times are thread CPU time (the machine running the benchmarks is shared; wall
// time there measures the neighbours). Wall-clock p99 is reported next to it.
double cpu_ms() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return double(ts.tv_sec) * 1e3 + double(ts.tv_nsec) * 1e-6;
}

struct Samples {
  std::vector<double> cpu, wall;
  double c0 = 0;
  std::chrono::steady_clock::time_point w0;
  void start() {
    c0 = cpu_ms();
    w0 = std::chrono::steady_clock::now();
  }
  void stop() {
    cpu.push_back(cpu_ms() - c0);
    wall.push_back(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - w0).count());
  }
  size_t size() const { return cpu.size(); }
};

void report(benchmark::State& state, Samples& s) {
  auto pct = [](std::vector<double>& v, double p) {
    std::sort(v.begin(), v.end());
    return v.empty() ? 0.0 : v[size_t(p * double(v.size() - 1))];
  };
  state.counters["p50_ms"] = pct(s.cpu, 0.50);
  state.counters["p99_ms"] = pct(s.cpu, 0.99);
  state.counters["max_ms"] = s.cpu.empty() ? 0.0 : s.cpu.back();
  state.counters["wall_p99_ms"] = pct(s.wall, 0.99);
}

void add_box_faces(std::vector<Vector3f>& pts, const Vector3f& lo, const Vector3f& hi) {
  for (float a = lo.x(); a <= hi.x(); a += 0.05f)
    for (float z = lo.z(); z <= hi.z(); z += 0.05f) {
      pts.emplace_back(a, lo.y(), z);
      pts.emplace_back(a, hi.y(), z);
    }
  for (float b = lo.y(); b <= hi.y(); b += 0.05f)
    for (float z = lo.z(); z <= hi.z(); z += 0.05f) {
      pts.emplace_back(lo.x(), b, z);
      pts.emplace_back(hi.x(), b, z);
    }
}

void BM_CycleMovingObstacle(benchmark::State& state) {
  Building& b = building();
  graph::MapChangeDetector detector;
  std::vector<graph::Aabb> changed, opened;
  std::vector<Vector3f> pts;
  Samples ms;
  double changed_blocks = 0, revalidated = 0, expanded = 0, evaluated = 0, boxes = 0;
  graph::FrontierUpdateStats fs_last;
  int step = 0;
  const float y = 3 * kRoom + kRoom / 2;
  // Prime the detector's signatures along the path (first sight of a block counts as changed).
  for (float x = 1.0f; x < kRoomsX * kRoom; x += 4.0f) {
    graph::Aabb all;
    all.extend(Vector3f(x - 6, y - 6, -1));
    all.extend(Vector3f(x + 6, y + 6, kHeight));
    changed.clear();
    detector.detect(b.map.view(), std::span(&all, 1), changed);
  }
  for (auto _ : state) {
    state.PauseTiming();
    const float x = 3.0f + 0.1f * float(step++ % 700);
    b.foot = Vector3f(x, y, 0);
    const Vector3f origin(x, y, 0.5f);
    const Vector3f ob(x + 1.5f, y + 0.3f, 0.0f);  // the person ahead of the robot
    pts.clear();
    for (float dx = -3.0f; dx <= 3.0f; dx += 0.1f)
      for (float dy = -3.0f; dy <= 3.0f; dy += 0.1f) {
        const Vector3f p(x + dx, y + dy, 0.0f);
        if (dx * dx + dy * dy <= 9.0f && !in_wall(p.x(), p.y()) &&
            !(std::abs(p.x() - ob.x()) < 0.3f && std::abs(p.y() - ob.y()) < 0.3f))
          pts.push_back(p);
      }
    add_box_faces(pts, ob - Vector3f(0.25f, 0.25f, 0.0f), ob + Vector3f(0.25f, 0.25f, 1.7f));
    b.map.insert_scan(origin, pts);
    b.map.update_traversability();
    b.map.update_reachable(b.foot);
    const graph::Aabb bounds = graph::scan_bounds(origin, pts);
    changed.clear();
    opened.clear();
    state.ResumeTiming();
    ms.start();
    changed_blocks +=
        double(detector.detect(b.map.view(), std::span(&bounds, 1), changed, &opened));
    const auto gs = b.graph->update(b.map.view(), b.foot, changed, b.rng);
    fs_last = b.frontiers->update(*b.graph, b.map.view(), b.foot, changed, opened);
    revalidated += gs.revalidated;
    expanded += gs.expanded;
    evaluated += fs_last.evaluated;
    boxes += double(changed.size());
    const auto& cl = b.clusters->update(*b.graph);
    ms.stop();
    benchmark::DoNotOptimize(cl.data());
  }
  report(state, ms);
  state.counters["nodes"] = double(b.graph->node_count());
  state.counters["edges"] = double(b.graph->edge_count());
  state.counters["frontiers"] = double(fs_last.frontiers);
  state.counters["clusters"] = double(b.clusters->clusters().size());
  const double n = double(std::max<size_t>(1, ms.size()));
  state.counters["changed_blocks"] = changed_blocks / n;
  state.counters["changed_boxes"] = boxes / n;
  state.counters["revalidated"] = revalidated / n;
  state.counters["expanded"] = expanded / n;
  state.counters["tf_evaluated"] = evaluated / n;
  state.SetItemsProcessed(int64_t(state.iterations()));
}
BENCHMARK(BM_CycleMovingObstacle)
    ->Name("graph/cycle_moving_obstacle")
    ->Unit(benchmark::kMillisecond)
    ->Iterations(600);

// Worst case: graph + frontiers + clusters with the whole +-m box reported changed.
void BM_GraphCycleRegion(benchmark::State& state) {
  Building& b = building();
  const float half = float(state.range(0));  // changed region: robot +- half [m]
  Samples ms;
  int step = 0;
  graph::FrontierUpdateStats fs_last;
  for (auto _ : state) {
    // The robot walks a loop through the middle row of rooms and back along another.
    const int k = step++ % (2 * kRoomsX);
    const int rx = k < kRoomsX ? k : 2 * kRoomsX - 1 - k;
    const int ry = k < kRoomsX ? 3 : 4;
    b.foot = Vector3f(rx * kRoom + kRoom / 2, ry * kRoom + kRoom / 2, 0);
    graph::Aabb changed;
    changed.extend(b.foot + Vector3f(-half, -half, -1.0f));
    changed.extend(b.foot + Vector3f(half, half, kHeight));
    ms.start();
    b.graph->update(b.map.view(), b.foot, std::span(&changed, 1), b.rng);
    fs_last = b.frontiers->update(*b.graph, b.map.view(), b.foot, std::span(&changed, 1),
                                  std::span(&changed, 1));
    const auto& cl = b.clusters->update(*b.graph);
    ms.stop();
    benchmark::DoNotOptimize(cl.data());
  }
  report(state, ms);
  state.counters["nodes"] = double(b.graph->node_count());
  state.counters["edges"] = double(b.graph->edge_count());
  state.counters["frontiers"] = double(fs_last.frontiers);
  state.counters["c_sur"] = double(fs_last.c_sur);
  state.counters["c_exp"] = double(fs_last.c_exp);
  state.counters["clusters"] = double(b.clusters->clusters().size());
  state.SetItemsProcessed(int64_t(state.iterations()));
}
BENCHMARK(BM_GraphCycleRegion)
    ->Name("graph/cycle_region")
    ->Arg(8)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(100);

// Baseline for the incremental update: every node revalidated (with its edges) and every
// node's frontier flags recomputed, as a from-scratch pass over the converged graph would.
void BM_GraphFullPass(benchmark::State& state) {
  Building& b = building();
  graph::GraphOptions all = b.opt;
  all.max_revalidations_per_update = 1 << 30;
  all.max_expansions_per_update = 0;
  graph::ReachableGraph& g = *b.graph;
  Samples ms;
  for (auto _ : state) {
    state.PauseTiming();
    graph::ReachableGraph copy = g;  // keep the shared graph untouched
    copy.touch_all();
    graph::TopologicalFrontiers tf(all);
    graph::FrontierClusters fc(all);
    state.ResumeTiming();
    ms.start();
    graph::GraphOptions o = all;
    copy.set_budgets(o.max_revalidations_per_update, 0, 0);
    copy.update(b.map.view(), b.foot, {}, b.rng);
    for (graph::NodeId i = 0; i < copy.node_capacity(); ++i)
      if (copy.node(i).alive) tf.evaluate(copy, b.map.view(), i);
    benchmark::DoNotOptimize(fc.update(copy).data());
    ms.stop();
  }
  report(state, ms);
  state.counters["nodes"] = double(g.node_count());
  state.SetItemsProcessed(int64_t(state.iterations()));
}
BENCHMARK(BM_GraphFullPass)->Name("graph/full_pass")->Unit(benchmark::kMillisecond)->Iterations(5);

// Viewpoint scoring (ray casting with the FOV and occlusion), per cluster.
void BM_ViewpointsPerCluster(benchmark::State& state) {
  Building& b = building();
  graph::ViewpointGenerator vg(
      b.opt, state.range(0) ? graph::SensorFov::mid360() : graph::SensorFov::vlp16());
  const auto& clusters = b.clusters->clusters();
  std::vector<graph::Viewpoint> out;
  Samples ms;
  size_t c = 0;
  for (auto _ : state) {
    if (clusters.empty()) break;
    ms.start();
    vg.generate(*b.graph, b.map.view(), clusters[c++ % clusters.size()], out);
    ms.stop();
    benchmark::DoNotOptimize(out.data());
  }
  report(state, ms);
  state.counters["clusters"] = double(clusters.size());
  state.SetItemsProcessed(int64_t(state.iterations()));
}
BENCHMARK(BM_ViewpointsPerCluster)
    ->Name("graph/viewpoints_per_cluster")
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMicrosecond)
    ->Iterations(2000);

}  // namespace
