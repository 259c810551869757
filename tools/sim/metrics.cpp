#include "tools/sim/metrics.hpp"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <stdexcept>
#include <unordered_set>

namespace storey::tools::sim {

Coverage compute_coverage(const GroundTruth& gt, const std::vector<VoxelKey>& trav,
                          const std::vector<VoxelKey>& occ) {
  Coverage c;
  const double v3 = std::pow(gt.resolution(), 3);
  std::unordered_set<VoxelKey, VoxelKeyHash> seen(trav.begin(), trav.end());
  c.observed_traversable_volume_m3 = double(seen.size()) * v3;
  std::unordered_set<VoxelKey, VoxelKeyHash> occ_set(occ.begin(), occ.end());
  c.observed_occupied_volume_m3 = double(occ_set.size()) * v3;
  const auto& floors = gt.floors();
  std::vector<std::size_t> hit(floors.size(), 0), total(floors.size(), 0);
  std::size_t covered = 0;
  for (const auto& k : gt.reachable_voxels()) {
    const bool h =
        seen.count(k) || seen.count({k.x, k.y, k.z - 1}) || seen.count({k.x, k.y, k.z + 1});
    covered += h ? 1 : 0;
    const int f = gt.floor_of(k);
    if (f >= 0) {
      ++total[f];
      hit[f] += h ? 1 : 0;
    }
  }
  const std::size_t n = gt.reachable_voxels().size();
  c.traversable_coverage = n ? double(covered) / double(n) : 0.0;
  for (std::size_t f = 0; f < floors.size(); ++f)
    c.per_floor.push_back(total[f] ? double(hit[f]) / double(total[f]) : 0.0);
  return c;
}

double CoverageTimeline::time_to(double fraction, int f) const {
  for (const auto& s : samples_) {
    const double v =
        f < 0 ? s.coverage : (std::size_t(f) < s.per_floor.size() ? s.per_floor[f] : 0.0);
    if (v >= fraction) return s.t;
  }
  return -1.0;
}

void fill_from_truth(const GroundTruth& gt, const Coverage& fc, const CoverageTimeline& tl,
                     double floor_done, RunMetrics& m) {
  m.floors_total = int(gt.floors().size());
  m.gt_traversable_volume_m3 = gt.traversable_volume_m3();
  m.gt_occupied_volume_m3 = gt.occupied_volume_m3();
  m.traversable_coverage = fc.traversable_coverage;
  m.traversable_volume_m3 = fc.observed_traversable_volume_m3;
  m.occupied_volume_m3 = fc.observed_occupied_volume_m3;
  m.per_floor.clear();
  m.floors_explored = 0;
  for (std::size_t f = 0; f < gt.floors().size(); ++f) {
    FloorMetrics fm;
    fm.z_m = gt.floors()[f].z_m;
    fm.traversable_coverage = f < fc.per_floor.size() ? fc.per_floor[f] : 0.0;
    fm.time_s = tl.time_to(floor_done, int(f));
    if (fm.traversable_coverage >= floor_done) ++m.floors_explored;
    m.per_floor.push_back(fm);
  }
  m.coverage_over_time.clear();
  for (const auto& s : tl.samples()) m.coverage_over_time.emplace_back(s.t, s.coverage);
}

std::string metrics_json(const RunMetrics& m) {
  std::string s;
  char b[512];
  auto add = [&](const char* fmt, auto... args) {
    std::snprintf(b, sizeof b, fmt, args...);
    s += b;
  };
  auto str = [](const std::string& v) {  // JSON string body: quotes, backslashes, controls
    std::string o;
    for (char c : v) {
      if (c == '"' || c == '\\')
        o += '\\', o += c;
      else if (static_cast<unsigned char>(c) >= 0x20)
        o += c;
    }
    return o;
  };
  s += "{\n  \"method\": \"" + str(m.method) + "\",\n  \"ablation\": \"" + str(m.ablation) +
       "\",\n  \"completed\": " + (m.completed ? "true" : "false") + ",\n  \"end_reason\": \"" +
       str(m.end_reason) + "\",\n  \"commit\": \"" + str(m.commit) + "\",\n";
  add("  \"success\": %s,\n  \"floors_total\": %d,\n  \"floors_explored\": %d,\n",
      m.success ? "true" : "false", m.floors_total, m.floors_explored);
  add("  \"exploration_time_s\": %.3f,\n  \"trajectory_length_m\": %.3f,\n", m.exploration_time_s,
      m.trajectory_length_m);
  add("  \"walking_time_s\": %.3f,\n", m.walking_time_s);
  add("  \"traversable_volume_m3\": %.3f,\n  \"occupied_volume_m3\": %.3f,\n",
      m.traversable_volume_m3, m.occupied_volume_m3);
  add("  \"gt_traversable_volume_m3\": %.3f,\n  \"gt_occupied_volume_m3\": %.3f,\n",
      m.gt_traversable_volume_m3, m.gt_occupied_volume_m3);
  add("  \"traversable_coverage\": %.4f,\n  \"per_floor\": [", m.traversable_coverage);
  for (std::size_t i = 0; i < m.per_floor.size(); ++i)
    add("%s\n    {\"z_m\": %.2f, \"time_s\": %.3f, \"traversable_coverage\": %.4f}", i ? "," : "",
        m.per_floor[i].z_m, m.per_floor[i].time_s, m.per_floor[i].traversable_coverage);
  add("\n  ],\n  \"collisions\": %u,\n  \"falls\": %u,\n  \"safety_stops\": %u,\n", m.collisions,
      m.falls, m.safety_stops);
  add("  \"tracking\": {\"side_p50_m\": %.3f, \"side_p99_m\": %.3f, \"side_max_m\": %.3f, "
      "\"ahead_max_m\": %.3f, \"samples\": %llu},\n  \"latency\": {",
      m.tracking.side_p50_m, m.tracking.side_p99_m, m.tracking.side_max_m, m.tracking.ahead_max_m,
      static_cast<unsigned long long>(m.tracking.samples));
  for (std::size_t i = 0; i < m.latency.size(); ++i) {
    std::string name;
    for (char c : m.latency[i].task)
      if (c != '"' && c != '\\' && static_cast<unsigned char>(c) >= 0x20) name += c;
    add("%s\n    \"%s\": {\"p50_ms\": %.3f, \"p99_ms\": %.3f, \"max_ms\": %.3f, \"overruns\": "
        "%llu}",
        i ? "," : "", name.c_str(), m.latency[i].p50_ms, m.latency[i].p99_ms, m.latency[i].max_ms,
        static_cast<unsigned long long>(m.latency[i].overruns));
  }
  add("\n  },\n  \"coverage_over_time\": [");
  for (std::size_t i = 0; i < m.coverage_over_time.size(); ++i)
    add("%s[%.3f, %.4f]", i ? ", " : "", m.coverage_over_time[i].first,
        m.coverage_over_time[i].second);
  add("]\n}\n");
  return s;
}

void write_metrics_json(const RunMetrics& m, const std::string& path) {
  std::ofstream f(path);
  if (!f) throw std::runtime_error(path + ": cannot open for writing");
  f << metrics_json(m);
  if (!f) throw std::runtime_error(path + ": write error");
}

}  // namespace storey::tools::sim
