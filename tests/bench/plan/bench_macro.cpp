// Full planning cycle of the ExplorationPlanner (paper Sec. IV: floors, hybrid-graph
// maintenance, global TSP over zones with two-stage costs, local Stage 1-3 and the B-spline) on
// a building-size world: two 48 x 36 m floors with a wall grid (rooms joined by doors), mapped
// by synthetic scans, the robot on floor 1 with the prior projected from floor 0.
// Reports p50/p99 of the cycle [ms] and the graph sizes as counters.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <memory>
#include <vector>

#include "core/plan/exploration_planner.hpp"
#include "tests/core_plan_macro/macro_world.hpp"

namespace {

using namespace storey::core;
using namespace storey::core::plan;
using storey::test::macro::Harness;
using storey::test::macro::World;

void building_floor(World& w, float z, bool all_doors_open) {
  w.add({-1, -1, z - 0.2f}, {49, 37, z});
  for (int i = 1; i < 4; ++i) {  // walls every 12 m along x, doors at y = 5, 17, 29
    const float x = 12.f * float(i);
    for (int j = 0; j < 3; ++j) {
      const float y0 = 12.f * float(j);
      const bool open = all_doors_open || (i + j) % 2 == 0;
      w.add({x, y0, z}, {x + 0.2f, y0 + 5, z + 2.5f});
      w.add({x, y0 + (open ? 6.f : 5.f), z}, {x + 0.2f, y0 + 12, z + 2.5f});
    }
  }
  for (int j = 1; j < 3; ++j) {  // walls every 12 m along y, doors at x = 5, 17, 29, 41
    const float y = 12.f * float(j);
    for (int i = 0; i < 4; ++i) {
      const float x0 = 12.f * float(i);
      w.add({x0, y, z}, {x0 + 5, y + 0.2f, z + 2.5f});
      w.add({x0 + 6, y, z}, {x0 + 12, y + 0.2f, z + 2.5f});
    }
  }
  w.add({-0.2f, -0.2f, z}, {48.2f, 0, z + 2.5f});
  w.add({-0.2f, 36, z}, {48.2f, 36.2f, z + 2.5f});
  w.add({-0.2f, -0.2f, z}, {0, 36.2f, z + 2.5f});
  w.add({48, -0.2f, z}, {48.2f, 36.2f, z + 2.5f});
}

struct Scene {
  World w;
  Harness h;
  std::unique_ptr<ExplorationPlanner> planner;
  Eigen::Vector3f foot;
  double t = 0;
};

Scene& scene() {
  static std::unique_ptr<Scene> s;
  if (s) return *s;
  s = std::make_unique<Scene>();
  building_floor(s->w, 0.f, true);
  building_floor(s->w, 3.f, false);  // floor 1: some doors closed (prior differs)
  s->planner = std::make_unique<ExplorationPlanner>(RobotModel{}, PlanOptions{}, 0.1);
  uint32_t seed = 1;
  // Floor 0: one scan per room centre and door.
  for (float x = 6; x < 48; x += 12)
    for (float y = 6; y < 36; y += 12) {
      const Eigen::Vector3f foot(x, y, 0);
      s->h.observe(s->w, foot, 40000, seed++);
      const auto view = s->h.map.view();
      ExplorationInput in{&view,
                          s->h.map.version(),
                          &s->h.graph,
                          &s->h.clusters.clusters(),
                          &s->h.viewpoints.viewpoints(),
                          foot.cast<double>(),
                          0,
                          s->t};
      s->planner->plan(in);
      s->t += 1;
    }
  // Floor 1 (the robot is carried up: the floor tracker sees a stable new height).
  for (float x = 6; x < 30; x += 12)
    for (float y = 6; y < 36; y += 12) {
      const Eigen::Vector3f foot(x, y, 3.f);
      s->h.observe(s->w, foot, 40000, seed++);
      for (int k = 0; k < 6; ++k) {
        const auto view = s->h.map.view();
        ExplorationInput in{&view,
                            s->h.map.version(),
                            &s->h.graph,
                            &s->h.clusters.clusters(),
                            &s->h.viewpoints.viewpoints(),
                            foot.cast<double>(),
                            0,
                            s->t};
        s->planner->plan(in);
        s->t += 0.5;
      }
      s->foot = foot;
    }
  return *s;
}

void BM_MacroPlanCycle(benchmark::State& st) {
  Scene& s = scene();
  std::vector<double> ms;
  size_t hybrid_nodes = 0;
  int zones = 0, new_traj = 0;
  for (auto _ : st) {
    s.planner->local().drop_target();  // force a full replan (Stage 1-3) every cycle
    const auto view = s.h.map.view();
    ExplorationInput in{&view,
                        s.h.map.version() + uint64_t(ms.size()),
                        &s.h.graph,
                        &s.h.clusters.clusters(),
                        &s.h.viewpoints.viewpoints(),
                        s.foot.cast<double>(),
                        0,
                        s.t};
    const auto t0 = std::chrono::steady_clock::now();
    const ExplorationResult r = s.planner->plan(in);
    ms.push_back(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    benchmark::DoNotOptimize(r.status);
    hybrid_nodes = s.planner->hybrid().nodes().size();
    zones = int(r.zones.size());
    new_traj += r.status == ExplorationStatus::kNewTrajectory;
  }
  std::sort(ms.begin(), ms.end());
  st.counters["p50_ms"] = ms[ms.size() / 2];
  st.counters["p99_ms"] = ms[std::min(ms.size() - 1, size_t(double(ms.size()) * 0.99))];
  st.counters["max_ms"] = ms.back();
  st.counters["real_nodes"] = double(s.h.graph.node_count());
  st.counters["hybrid_nodes"] = double(hybrid_nodes);
  st.counters["zones"] = zones;
  st.counters["clusters"] = double(s.h.clusters.clusters().size());
  st.counters["new_traj_frac"] = double(new_traj) / double(ms.size());
}
BENCHMARK(BM_MacroPlanCycle)->Unit(benchmark::kMillisecond)->Iterations(30);

}  // namespace
