// core/map benchmarks: scan insertion against OctoMap (same scans, resolution and max range),
// traversability + reachable-set update latency, memory per m^2 of explored floor.
// See docs/PERFORMANCE.md, section "map".
#include <algorithm>
#include <chrono>
#include <ctime>
#include <memory>
#include <set>
#include <utility>
#include <vector>

#include <benchmark/benchmark.h>
#include <octomap/octomap.h>

#include "core/map/traversability_map.hpp"
#include "tests/core_map/synthetic_world.hpp"

namespace {
using Eigen::Vector3f;
using storey::core::map::MapOptions;
using storey::core::map::TraversabilityMap;

constexpr double kVoxel = 0.1, kMaxRange = 30.0;

struct ScanSet {
  std::vector<Vector3f> origins;
  std::vector<std::vector<Vector3f>> scans;
  size_t points = 0;
};

// The robot walks the corridor of the office box world and looks into the rooms.
const ScanSet& scans(bool vlp16) {
  static std::unique_ptr<ScanSet> sets[2];
  auto& s = sets[vlp16 ? 0 : 1];
  if (s) return *s;
  s = std::make_unique<ScanSet>();
  const storey::test::World w = storey::test::office_box_world();
  uint32_t frame = 0;
  for (float x = -16.f; x <= 16.f; x += 1.0f) {
    const Vector3f o(x, 0.3f * std::sin(x), 0.5f);
    s->origins.push_back(o);
    s->scans.push_back(vlp16 ? storey::test::scan_vlp16(w, o, 0.1f * x, frame)
                             : storey::test::scan_mid360(w, o, frame));
    s->points += s->scans.back().size();
    ++frame;
  }
  return *s;
}

double thread_cpu_s() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

MapOptions bench_options() {
  MapOptions o;
  o.voxel_size_m = kVoxel;
  o.max_range_m = kMaxRange;
  return o;
}

void insert_storey(benchmark::State& state, bool vlp16, bool exact = false, bool crossing = false,
                   bool from_above = false) {
  const ScanSet& set = scans(vlp16);
  MapOptions o = bench_options();
  if (exact) o.ray_early_stop_voxels = 0;  // every voxel of every ray, like OctoMap
  o.miss_needs_crossing = crossing;        // map.miss_needs_crossing
  o.floor_seen_from_above = from_above;    // map.floor_seen_from_above
  TraversabilityMap map(o);
  size_t i = 0, points = 0;
  for (auto _ : state) {
    const auto st = map.insert_scan(set.origins[i], set.scans[i]);
    benchmark::DoNotOptimize(st);
    points += set.scans[i].size();
    i = (i + 1) % set.scans.size();
  }
  state.SetItemsProcessed(int64_t(points));
  state.counters["points_per_scan"] = double(set.points) / double(set.scans.size());
}

void insert_octomap(benchmark::State& state, bool vlp16) {
  const ScanSet& set = scans(vlp16);
  // Same scans as octomap::Pointcloud, converted once outside the timed loop.
  std::vector<octomap::Pointcloud> clouds(set.scans.size());
  for (size_t k = 0; k < set.scans.size(); ++k)
    for (const Vector3f& p : set.scans[k]) clouds[k].push_back(p.x(), p.y(), p.z());
  octomap::OcTree tree(kVoxel);
  size_t i = 0, points = 0;
  for (auto _ : state) {
    const Vector3f& o = set.origins[i];
    tree.insertPointCloud(clouds[i], octomap::point3d(o.x(), o.y(), o.z()), kMaxRange);
    points += set.scans[i].size();
    i = (i + 1) % set.scans.size();
  }
  state.SetItemsProcessed(int64_t(points));
}

void BM_map_insert_vlp16_storey(benchmark::State& s) {
  insert_storey(s, true);
}
void BM_map_insert_vlp16_octomap(benchmark::State& s) {
  insert_octomap(s, true);
}
void BM_map_insert_vlp16_exact(benchmark::State& s) {
  insert_storey(s, true, true);
}
void BM_map_insert_mid360_exact(benchmark::State& s) {
  insert_storey(s, false, true);
}
void BM_map_insert_mid360_storey(benchmark::State& s) {
  insert_storey(s, false);
}
// map.miss_needs_crossing: the plane tests of occupied voxels a ray meets.
void BM_map_insert_vlp16_crossing(benchmark::State& s) {
  insert_storey(s, true, false, true);
}
void BM_map_insert_mid360_crossing(benchmark::State& s) {
  insert_storey(s, false, false, true);
}
// map.floor_seen_from_above (with the default miss_needs_crossing): each hit's rise.
void BM_map_insert_vlp16_from_above(benchmark::State& s) {
  insert_storey(s, true, false, true, true);
}
void BM_map_insert_mid360_from_above(benchmark::State& s) {
  insert_storey(s, false, false, true, true);
}
void BM_map_insert_mid360_octomap(benchmark::State& s) {
  insert_octomap(s, false);
}

// Per scan at the VLP-16 rate: update_traversability() + update_reachable() after the scan's
// insertion (insertion not timed here). Manual time; p50/p99/max as counters.
void BM_map_update_vlp16_storey(benchmark::State& state) {
  const ScanSet& set = scans(true);
  TraversabilityMap map(bench_options());
  std::vector<double> ms, cpu_ms;  // wall (includes preemption on a shared machine) and CPU
  size_t i = 0;
  for (auto _ : state) {
    map.insert_scan(set.origins[i], set.scans[i]);
    const double c0 = thread_cpu_s();
    const auto t0 = std::chrono::steady_clock::now();
    const auto tu = map.update_traversability();
    const auto ru = map.update_reachable(set.origins[i] - Vector3f(0, 0, 0.5f));
    const auto t1 = std::chrono::steady_clock::now();
    cpu_ms.push_back((thread_cpu_s() - c0) * 1e3);
    benchmark::DoNotOptimize(tu);
    benchmark::DoNotOptimize(ru);
    const double dt = std::chrono::duration<double>(t1 - t0).count();
    state.SetIterationTime(dt);
    ms.push_back(dt * 1e3);
    i = (i + 1) % set.scans.size();
  }
  std::sort(ms.begin(), ms.end());
  std::sort(cpu_ms.begin(), cpu_ms.end());
  auto pct = [](const std::vector<double>& v, double p) {
    return v[std::min(v.size() - 1, size_t(p * double(v.size())))];
  };
  state.counters["p50_ms"] = pct(ms, 0.50);
  state.counters["p99_ms"] = pct(ms, 0.99);
  state.counters["max_ms"] = ms.back();
  state.counters["cpu_p50_ms"] = pct(cpu_ms, 0.50);
  state.counters["cpu_p99_ms"] = pct(cpu_ms, 0.99);
  state.counters["cpu_max_ms"] = cpu_ms.back();
  state.counters["reachable_m3"] = map.reachable_volume_m3();
  state.counters["traversable_m3"] = map.traversable_volume_m3();
}

// Memory of the whole map after the robot walked the corridor, per m^2 of explored floor
// (observed floor-level support area, 1 voxel = 0.01 m^2).
void BM_map_memory_vlp16_storey(benchmark::State& state) {
  const ScanSet& set = scans(true);
  TraversabilityMap map(bench_options());
  for (auto _ : state) {
    for (size_t i = 0; i < set.scans.size(); ++i) {
      map.insert_scan(set.origins[i], set.scans[i]);
      map.update_traversability();
      map.update_reachable(set.origins[i] - Vector3f(0, 0, 0.5f));
    }
  }
  // Explored floor: the footprint of the map, i.e. the (x, y) columns holding any observed
  // voxel (the storey's free space, walls and floor over that area are all in memory).
  std::set<std::pair<int32_t, int32_t>> columns;
  size_t floor_voxels = 0;
  map.view().store().for_each([&](const storey::core::map::VoxelBlock& b) {
    for (int i = 0; i < storey::core::map::kBlockCells; ++i)
      if (b.cells[i].flags & storey::core::map::Cell::kObserved)
        columns.emplace((b.bx << 3) | (i >> 6), (b.by << 3) | ((i >> 3) & 7));
  });
  map.view().for_each_occupied([&](const auto& k, const auto&, const auto*) {
    floor_voxels += (k.z == -1 || k.z == 0) && map.view().is_support(k);
  });
  const double area = double(columns.size()) * kVoxel * kVoxel;
  state.counters["mem_MiB"] = double(map.mem_usage()) / (1 << 20);
  state.counters["footprint_m2"] = area;
  state.counters["floor_support_m2"] = double(floor_voxels) * kVoxel * kVoxel;
  state.counters["bytes_per_m2"] = double(map.mem_usage()) / std::max(1.0, area);
  state.counters["blocks"] = double(map.view().store().block_count());
}
}  // namespace

BENCHMARK(BM_map_insert_vlp16_storey)
    ->Name("map_insert_vlp16/storey")
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_map_insert_vlp16_octomap)
    ->Name("map_insert_vlp16/octomap")
    ->Unit(benchmark::kMillisecond)
    ->Iterations(33);
BENCHMARK(BM_map_insert_mid360_storey)
    ->Name("map_insert_mid360/storey")
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_map_insert_mid360_octomap)
    ->Name("map_insert_mid360/octomap")
    ->Unit(benchmark::kMillisecond)
    ->Iterations(33);
BENCHMARK(BM_map_insert_vlp16_crossing)
    ->Name("map_insert_vlp16/storey_crossing")
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_map_insert_mid360_crossing)
    ->Name("map_insert_mid360/storey_crossing")
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_map_insert_vlp16_from_above)
    ->Name("map_insert_vlp16/storey_crossing_from_above")
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_map_insert_mid360_from_above)
    ->Name("map_insert_mid360/storey_crossing_from_above")
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_map_insert_vlp16_exact)
    ->Name("map_insert_vlp16/storey_exact")
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_map_insert_mid360_exact)
    ->Name("map_insert_mid360/storey_exact")
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_map_update_vlp16_storey)
    ->Name("map_update_vlp16/storey")
    ->Unit(benchmark::kMillisecond)
    ->UseManualTime()
    ->Iterations(330);
BENCHMARK(BM_map_memory_vlp16_storey)
    ->Name("map_memory_vlp16/storey")
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);
