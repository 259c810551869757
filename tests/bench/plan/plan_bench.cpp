// Planning benchmarks (paper Sec. IV): TSP solve vs n, the Stage-2 viewpoint DP (W = 4, K = 8),
// voxel A* and trajectory on a building-size map, and the control task's FCL look-ahead
// (1 s of trajectory sampled at 50 Hz).
#include <benchmark/benchmark.h>

#include <cmath>
#include <memory>
#include <optional>
#include <random>
#include <vector>

#include "core/plan/bspline_trajectory.hpp"
#include "core/plan/collision_checker.hpp"
#include "core/plan/tsp.hpp"
#include "core/plan/viewpoint_dp.hpp"
#include "core/plan/voxel_astar.hpp"
#include "tests/core_plan/voxel_world.hpp"

namespace {

using namespace storey::core;
using namespace storey::core::plan;

std::vector<double> euclid_matrix(int n, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0, 40);
  std::vector<double> x(n), y(n), c(size_t(n) * n);
  for (int i = 0; i < n; ++i) x[i] = u(rng), y[i] = u(rng);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) c[size_t(i) * n + j] = std::hypot(x[i] - x[j], y[i] - y[j]);
  return c;
}

void BM_PlanTsp(benchmark::State& st) {
  const int n = int(st.range(0));
  const bool heuristic = st.range(1) != 0;
  const auto c = euclid_matrix(n, 17);
  TspSolver solver;
  double cost = 0;
  for (auto _ : st) {
    const TspResult r =
        heuristic ? solver.solve_heuristic({n, c}, 0, n - 1) : solver.solve_exact({n, c}, 0, n - 1);
    cost = r.cost;
    benchmark::DoNotOptimize(cost);
  }
  st.SetItemsProcessed(st.iterations());
}
BENCHMARK(BM_PlanTsp)
    ->ArgNames({"n", "heuristic"})
    ->Args({8, 0})
    ->Args({10, 0})
    ->Args({12, 0})
    ->Args({8, 1})
    ->Args({12, 1})
    ->Args({20, 1})
    ->Args({50, 1})
    ->Args({100, 1})
    ->Unit(benchmark::kMicrosecond);

void BM_PlanViewpointDp(benchmark::State& st) {
  const int w = 4, k = 8;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-10, 10), yaw(-M_PI, M_PI);
  std::vector<std::vector<Viewpoint>> cl(static_cast<size_t>(w));
  for (auto& c : cl)
    for (int i = 0; i < k; ++i) c.push_back({{u(rng), u(rng), 0}, yaw(rng)});
  const Viewpoint x0{{0, 0, 0}, 0};
  const Viewpoint anchor{{15, 0, 0}, 0};
  // d() stands for a cached graph path cost: Euclidean here, so the DP itself is measured.
  auto d = [](const Viewpoint& a, const Viewpoint& b) { return (a.p_m - b.p_m).norm(); };
  ViewpointDp dp(ViewpointDpOptions{.window_w = w});
  for (auto _ : st) {
    const DpResult r = dp.solve(x0, cl, anchor, d);
    benchmark::DoNotOptimize(r.cost);
  }
  st.SetItemsProcessed(st.iterations());
}
BENCHMARK(BM_PlanViewpointDp)->Unit(benchmark::kMicrosecond);

// The office box world of the map benchmarks (40 x 20 m, rooms along a corridor), scanned from
// points along the corridor and inside a few rooms.
struct Building {
  map::TraversabilityMap map;
  Building() {
    std::vector<Eigen::Vector3f> origins;
    for (float x = -17.5f; x <= 17.5f; x += 2.5f) origins.push_back({x, 0, 0.5f});
    for (float x = -17.5f; x <= 17.5f; x += 5.0f) {
      origins.push_back({x, 5.5f, 0.5f});
      origins.push_back({x, -5.5f, 0.5f});
    }
    for (int i = -3; i <= 3; ++i) {  // in each doorway, so the thresholds are observed
      origins.push_back({5.0f * i + 1.5f, 2.0f, 0.5f});
      origins.push_back({5.0f * i + 1.5f, -2.0f, 0.5f});
    }
    storey::test::scan_world(map, storey::test::office_box_world(), origins, 40000);
  }
};
Building& building() {
  static Building b;
  return b;
}

void BM_PlanVoxelAStar(benchmark::State& st) {
  const map::MapView view = building().map.view();
  VoxelAStar astar;
  const Eigen::Vector3d start(-17.5, 0, 0), goal(st.range(0) == 0 ? -7.5 : 16.0, 5.5, 0);
  VoxelPath p;
  for (auto _ : st) {
    p = astar.plan(view, start, goal);
    benchmark::DoNotOptimize(p.cost);
  }
  if (p.status != VoxelAStarStatus::kOk) st.SkipWithError(to_string(p.status));
  st.counters["expansions"] = p.expansions;
  st.counters["path_m"] = p.cost;
  st.SetItemsProcessed(st.iterations());
}
BENCHMARK(BM_PlanVoxelAStar)
    ->ArgName("far")
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(5);

// The 14.3 m path from the corridor into a room through a 1 m door (BM_PlanVoxelAStar far:0);
// nullopt (the benchmark skipped) if A* fails.
std::optional<VoxelPath> door_path(benchmark::State& st, const map::MapView& view) {
  VoxelAStar astar;
  VoxelPath p = astar.plan(view, {-17.5, 0, 0}, {-7.5, 5.5, 0});
  if (p.status == VoxelAStarStatus::kOk) return p;
  st.SkipWithError(to_string(p.status));
  return std::nullopt;
}

void BM_PlanTrajectory(benchmark::State& st) {
  const map::MapView view = building().map.view();
  const std::optional<VoxelPath> p = door_path(st, view);
  if (!p) return;
  RobotModel robot;
  CollisionChecker cc(robot, view.voxel_size_m());
  TrajectoryBuilder tb(robot, TrajectoryOptions{.retime = st.range(0) != 0});
  TrajectoryResult r;
  for (auto _ : st) {
    r = tb.build(view, cc, p->points_m, 0.0, M_PI / 2, 0.0);
    benchmark::DoNotOptimize(r.trajectory.duration());
  }
  st.counters["ok"] = r.status == TrajectoryStatus::kOk || r.status == TrajectoryStatus::kPolyline;
  st.counters["waypoints"] = double(r.waypoints_m.size());
  st.counters["segment_checks"] = r.segment_checks;
  st.counters["duration_s"] = r.trajectory.duration();
  st.SetItemsProcessed(st.iterations());
}
// retime:1 = TrajectoryOptions::retime (the same curve, time-optimal profile).
BENCHMARK(BM_PlanTrajectory)
    ->ArgName("retime")
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(5);

// One sample of the built trajectory (the control task's reference each period, the look-ahead's
// poses): uniform time against the re-timed table's lookup.
void BM_PlanTrajectorySample(benchmark::State& st) {
  const map::MapView view = building().map.view();
  const std::optional<VoxelPath> p = door_path(st, view);
  if (!p) return;
  RobotModel robot;
  CollisionChecker cc(robot, view.voxel_size_m());
  const TrajectoryResult r = TrajectoryBuilder(robot, TrajectoryOptions{.retime = st.range(0) != 0})
                                 .build(view, cc, p->points_m, 0.0, M_PI / 2, 0.0);
  const BsplineTrajectory& t = r.trajectory;
  double s = t.t_start();
  for (auto _ : st) {
    benchmark::DoNotOptimize(t.sample(s).p_m.x());
    s = s > t.t_end() ? t.t_start() : s + 0.013;
  }
  st.counters["duration_s"] = t.duration();
  st.SetItemsProcessed(st.iterations());
}
BENCHMARK(BM_PlanTrajectorySample)->ArgName("retime")->Arg(0)->Arg(1)->Unit(benchmark::kNanosecond);

void BM_PlanLookahead(benchmark::State& st) {
  const map::MapView view = building().map.view();
  RobotModel robot;
  CollisionChecker cc(robot, view.voxel_size_m());
  // Walking the corridor past door frames at 1 m/s: 1 s ahead, sampled at 50 Hz (51 poses).
  // 0.25 m from the corridor wall line (y = 1.95), so wall and door-frame voxels are loaded.
  auto pose = [](double t) { return BodyPose{{-17.0 + t, 1.5, 0.0}, 0.0}; };
  CollisionHit h;
  double t0 = 0;
  for (auto _ : st) {
    h = cc.check_ahead(view, pose, t0, 1.0, 0.02);
    t0 = t0 > 30 ? 0 : t0 + 0.02;
    benchmark::DoNotOptimize(h.collides);
  }
  st.counters["poses"] = h.poses_checked;
  st.counters["voxels"] = h.voxels_loaded;
  st.SetItemsProcessed(st.iterations());
}
BENCHMARK(BM_PlanLookahead)->Unit(benchmark::kMicrosecond);

}  // namespace
