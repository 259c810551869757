// Full planning cycle of the ExplorationPlanner (paper Sec. IV: floors, hybrid-graph
// maintenance, global TSP over zones with two-stage costs, local Stage 1-3 and the B-spline) on
// a building-size world: two 48 x 36 m floors with a wall grid (rooms joined by doors), mapped
// by synthetic scans, the robot on floor 1 with the prior projected from floor 0.
// Reports p50/p99 of the cycle [ms] (wall clock and the thread's CPU time: the machine is
// shared), the mean time per stage [ms] (StageProbe) and the graph sizes as counters.
#include <benchmark/benchmark.h>
#include <time.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <memory>
#include <string>
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

double thread_cpu_ms() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return double(ts.tv_sec) * 1e3 + double(ts.tv_nsec) * 1e-6;
}

// Wall time per stage of one cycle (the planner marks stage boundaries).
struct StageClock final : StageProbe {
  using Clock = std::chrono::steady_clock;
  std::array<double, size_t(PlanStage::kCount)> ms{};
  PlanStage cur = PlanStage::kDone;
  Clock::time_point t0 = Clock::now();
  void mark(PlanStage s) override {
    const Clock::time_point t = Clock::now();
    if (cur != PlanStage::kDone)
      ms[size_t(cur)] += std::chrono::duration<double, std::milli>(t - t0).count();
    cur = s;
    t0 = t;
  }
};

double percentile(std::vector<double> v, double q) {
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, size_t(double(v.size()) * q))];
}

struct Scene {
  World w;
  Harness h;
  std::unique_ptr<ExplorationPlanner> planner;
  Eigen::Vector3f foot;
  double t = 0;
  double prior_cycle_ms = 0;  // the cycle that built the prior (zones + projection), wall
  double setup_max_ms = 0;    // slowest cycle while mapping (new scans every cycle), wall
  StageClock probe;
  std::array<double, size_t(PlanStage::kCount)> prior_stages{};  // of the prior cycle
  // Times one setup cycle.
  void plan(const ExplorationInput& in) {
    planner->set_stage_probe(&probe);
    probe.ms.fill(0);
    const auto t0 = std::chrono::steady_clock::now();
    const ExplorationResult r = planner->plan(in);
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    setup_max_ms = std::max(setup_max_ms, ms);
    if (r.prior_built) {
      prior_cycle_ms = ms;
      prior_stages = probe.ms;
    }
    planner->set_stage_probe(nullptr);
  }
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
      s->plan(in);
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
        s->plan(in);
        s->t += 0.5;
      }
      s->foot = foot;
    }
  return *s;
}

// Arg 0: the map's changed regions are unknown (every hypothesis within hyp_check_radius_m is
// re-checked each cycle: the worst case). Arg 1: the caller passes them; each cycle the map
// changed within 6 m of the robot (what a scan from a standing robot rewrites).
void BM_MacroPlanCycle(benchmark::State& st) {
  Scene& s = scene();
  std::vector<graph::Aabb> changed(1);
  changed[0].extend(s.foot + Eigen::Vector3f(-6, -6, -1));
  changed[0].extend(s.foot + Eigen::Vector3f(6, 6, 2.5f));
  StageClock probe;
  s.planner->set_stage_probe(&probe);
  std::array<double, size_t(PlanStage::kCount)> stage_sum{};
  std::vector<double> ms, cpu_ms;
  size_t hybrid_nodes = 0;
  int zones = 0, new_traj = 0;
  int target_cluster = -1, zone0 = -1, zone1 = -1,
      zone2 = -1;  // the decision (same every cycle here)
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
    if (st.range(0) == 1) in.changed_regions = &changed;
    probe.ms.fill(0);
    const double c0 = thread_cpu_ms();
    const auto t0 = std::chrono::steady_clock::now();
    const ExplorationResult r = s.planner->plan(in);
    ms.push_back(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    cpu_ms.push_back(thread_cpu_ms() - c0);
    for (size_t k = 0; k < stage_sum.size(); ++k) stage_sum[k] += probe.ms[k];
    benchmark::DoNotOptimize(r.status);
    hybrid_nodes = s.planner->hybrid().nodes().size();
    zones = int(r.zones.size());
    new_traj += r.status == ExplorationStatus::kNewTrajectory;
    target_cluster = r.target_cluster;
    zone0 = r.zone_sequence.empty() ? -1 : r.zone_sequence[0];
    zone1 = r.zone_sequence.size() < 2 ? -1 : r.zone_sequence[1];
    zone2 = r.zone_sequence.size() < 3 ? -1 : r.zone_sequence[2];
  }
  s.planner->set_stage_probe(nullptr);
  st.counters["p50_ms"] = percentile(ms, 0.5);
  st.counters["p99_ms"] = percentile(ms, 0.99);
  st.counters["max_ms"] = percentile(ms, 1.0);
  st.counters["cpu_p50_ms"] = percentile(cpu_ms, 0.5);
  st.counters["cpu_p99_ms"] = percentile(cpu_ms, 0.99);
  for (size_t k = 0; k + 1 < stage_sum.size(); ++k)  // mean wall time per stage (kDone: none)
    st.counters[std::string("stage_") + to_string(PlanStage(k)) + "_ms"] =
        stage_sum[k] / double(ms.size());
  st.counters["prior_cycle_ms"] = s.prior_cycle_ms;
  st.counters["setup_max_ms"] = s.setup_max_ms;
  for (size_t k = 0; k + 1 < s.prior_stages.size(); ++k)
    if (s.prior_stages[k] > 0.5)
      st.counters[std::string("prior_cycle_") + to_string(PlanStage(k)) + "_ms"] =
          s.prior_stages[k];
  st.counters["real_nodes"] = double(s.h.graph.node_count());
  st.counters["hybrid_nodes"] = double(hybrid_nodes);
  st.counters["zones"] = zones;
  st.counters["target_cluster"] = target_cluster;
  st.counters["zone_seq_0"] = zone0;
  st.counters["zone_seq_1"] = zone1;
  st.counters["zone_seq_2"] = zone2;
  st.counters["clusters"] = double(s.h.clusters.clusters().size());
  st.counters["new_traj_frac"] = double(new_traj) / double(ms.size());
}
BENCHMARK(BM_MacroPlanCycle)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->Iterations(200);

}  // namespace
