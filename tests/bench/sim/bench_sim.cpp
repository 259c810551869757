// Simulated LiDAR sweeps per second against real time (10 Hz): counters `scans_per_s` and
// `x_realtime` (= scans_per_s / 10). DESIGN bar: >= 5x real time per sensor on one core.
// Needs storey_sim in storey-bench's link list (tests/bench/CMakeLists.txt).
#include <benchmark/benchmark.h>

#include <string>

#include "tools/sim/lidar_model.hpp"
#include "tools/sim/ray_caster.hpp"
#include "tools/sim/scene.hpp"
#include "tools/sim/world_sim.hpp"

namespace sim = storey::tools::sim;

namespace {

void scan_bench(benchmark::State& state, sim::LidarType type, const char* scene_name) {
  const sim::Scene scene = sim::load_scene(scene_name);
  const sim::RayCaster rc(scene.mesh);
  sim::LidarOptions o;
  o.type = type;
  sim::LidarModel lidar(rc, o);
  sim::LidarScan scan;
  // The robot moves during the sweep (1 m/s forward, 0.5 rad/s).
  const sim::StartPose st = *scene.start;
  const auto pose = [&](double t) {
    return Eigen::Isometry3d(Eigen::Translation3d(st.x + t, st.y, st.z) *
                             Eigen::AngleAxisd(st.yaw + 0.5 * t, Eigen::Vector3d::UnitZ()));
  };
  double t = 0.0;
  std::size_t points = 0;
  for (auto _ : state) {
    lidar.scan(t, pose, scan);
    points += scan.size();
    t = std::fmod(t + 0.1, 2.0);
    benchmark::DoNotOptimize(scan.points_world.data());
  }
  state.SetItemsProcessed(state.iterations() * int64_t(lidar.rays_per_scan()));
  state.counters["scans_per_s"] =
      benchmark::Counter(double(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["x_realtime"] =
      benchmark::Counter(double(state.iterations()) * o.scan_period, benchmark::Counter::kIsRate);
  state.counters["returns_per_scan"] = double(points) / double(state.iterations());
}

// A whole lockstep second (robot physics at 200 Hz + 10 sweeps) per iteration.
void world_bench(benchmark::State& state, sim::LidarType type) {
  const sim::Scene scene = sim::load_scene("office");
  sim::SimOptions o;
  o.lidar.type = type;
  sim::WorldSim w(scene, o);
  for (auto _ : state) {
    for (int i = 0; i < 50; ++i) w.step(0.02, {0.3, 0.0, 0.2});
    benchmark::DoNotOptimize(w.take_scan());
  }
  state.counters["x_realtime"] =
      benchmark::Counter(double(state.iterations()), benchmark::Counter::kIsRate);
}

}  // namespace

// Registered by hand for exact names: sim_scan_<sensor>/<scene>, sim_lockstep_second/<sensor>.
const bool kRegistered = [] {
  for (const char* scene : {"office", "teaching_building"}) {
    benchmark::RegisterBenchmark((std::string("sim_scan_vlp16/") + scene).c_str(), scan_bench,
                                 sim::LidarType::vlp16, scene)
        ->Unit(benchmark::kMillisecond);
    benchmark::RegisterBenchmark((std::string("sim_scan_mid360/") + scene).c_str(), scan_bench,
                                 sim::LidarType::mid360, scene)
        ->Unit(benchmark::kMillisecond);
  }
  benchmark::RegisterBenchmark("sim_lockstep_second/vlp16", world_bench, sim::LidarType::vlp16)
      ->Unit(benchmark::kMillisecond);
  benchmark::RegisterBenchmark("sim_lockstep_second/mid360", world_bench, sim::LidarType::mid360)
      ->Unit(benchmark::kMillisecond);
  return true;
}();
