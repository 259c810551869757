#include "core/plan/task_zones.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace storey::core::plan {

void compute_zone_centre(std::span<const Eigen::Vector3d> positions_m, TaskZone& z) {
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (uint32_t u : z.nodes) c += positions_m[u];
  if (!z.nodes.empty()) c /= double(z.nodes.size());
  z.centroid_m = c;
  double best = std::numeric_limits<double>::infinity();
  z.centre = kNoNode;
  for (uint32_t u : z.nodes) {  // ascending: ties keep the lower index
    const double d = (positions_m[u] - c).squaredNorm();
    if (d < best) {
      best = d;
      z.centre = u;
    }
  }
}

ZonePartition TaskZonePartitioner::partition(const SearchGraph& g,
                                             std::span<const double> clearance_m,
                                             const ZoneOptions& opt) {
  ZonePartition out;
  const size_t n = g.num_nodes();
  out.zone_of.assign(n, -1);
  if (clearance_m.size() != n || !(opt.r_z_m > 0)) {
    ++bad_input_;
    return out;
  }
  // Seed order: clearance descending, index ascending (NaN clearances rank last).
  order_.resize(n);
  for (uint32_t i = 0; i < n; ++i) order_[i] = i;
  auto key = [&](uint32_t u) {
    const double c = clearance_m[u];
    return std::isfinite(c) ? c : -std::numeric_limits<double>::infinity();
  };
  std::stable_sort(order_.begin(), order_.end(),
                   [&](uint32_t a, uint32_t b) { return key(a) > key(b); });
  best_.assign(n, std::numeric_limits<double>::infinity());
  int32_t zones = 0;
  size_t next = 0;
  for (;;) {
    while (next < n && out.zone_of[order_[next]] >= 0) ++next;
    if (next == n) break;
    const uint32_t seed = order_[next];
    const int32_t z = zones++;
    // Bounded Dijkstra to r_z; claim every node for which this seed is strictly closer.
    for (const Settled& s : search_.dijkstra(g, std::span<const uint32_t>(&seed, 1), opt.r_z_m)) {
      if (s.dist < best_[s.node]) {
        best_[s.node] = s.dist;
        out.zone_of[s.node] = z;
      }
    }
  }
  // Absorb small zones into the adjacent zone with the most cross edges (smallest first).
  std::vector<int> size(size_t(zones), 0);
  for (int32_t z : out.zone_of) ++size[size_t(z)];
  std::vector<int> cross(size_t(zones), 0);
  for (bool changed = true; changed;) {
    changed = false;
    int32_t pick = -1;
    for (int32_t z = 0; z < zones; ++z)
      if (size[size_t(z)] > 0 && size[size_t(z)] < opt.min_zone_nodes &&
          (pick < 0 || size[size_t(z)] < size[size_t(pick)]))
        pick = z;
    if (pick < 0) break;
    std::fill(cross.begin(), cross.end(), 0);
    for (uint32_t u = 0; u < n; ++u) {
      if (out.zone_of[u] != pick) continue;
      g.for_each_edge(u, [&](uint32_t v, double, uint32_t) {
        const int32_t zv = out.zone_of[v];
        if (zv != pick) ++cross[size_t(zv)];
      });
    }
    int32_t into = -1;
    for (int32_t z = 0; z < zones; ++z)
      if (cross[size_t(z)] > 0 && (into < 0 || cross[size_t(z)] > cross[size_t(into)])) into = z;
    if (into < 0) {
      size[size_t(pick)] = -size[size_t(pick)];  // isolated: keep it, never pick again
      changed = true;
      continue;
    }
    for (uint32_t u = 0; u < n; ++u)
      if (out.zone_of[u] == pick) out.zone_of[u] = into;
    size[size_t(into)] += size[size_t(pick)];
    size[size_t(pick)] = 0;
    changed = true;
  }
  // Renumber densely in order of first appearance by node index; centres.
  std::vector<int32_t> remap(size_t(zones), -1);
  for (uint32_t u = 0; u < n; ++u) {
    int32_t& r = remap[size_t(out.zone_of[u])];
    if (r < 0) {
      r = int32_t(out.zones.size());
      out.zones.emplace_back();
      out.zones.back().id = r;
    }
    out.zone_of[u] = r;
    out.zones[size_t(r)].nodes.push_back(u);
  }
  for (TaskZone& z : out.zones) compute_zone_centre(g.positions_m, z);
  return out;
}

void ObstacleClearance::build(double voxel_m) {
  offsets_.clear();
  const int r = int(std::ceil(max_radius_m_ / voxel_m));
  for (int dx = -r; dx <= r; ++dx)
    for (int dy = -r; dy <= r; ++dy) {
      const float d = float(std::hypot(dx, dy) * voxel_m);
      if (d <= max_radius_m_) offsets_.push_back({int16_t(dx), int16_t(dy), d});
    }
  std::stable_sort(offsets_.begin(), offsets_.end(),
                   [](const Offset& a, const Offset& b) { return a.dist_m < b.dist_m; });
  built_for_voxel_m_ = voxel_m;
}

double ObstacleClearance::operator()(const map::MapView& view, const Eigen::Vector3f& p) {
  const double v = view.voxel_size_m();
  if (v != built_for_voxel_m_) build(v);
  if (!p.allFinite()) return 0;
  const RobotModel& robot = view.robot();
  const map::VoxelKey base = view.key_of(p);
  const int z_lo = view.key_of(p + Eigen::Vector3f(0, 0, float(robot.step_height_m + v * 0.5))).z;
  const int z_hi = view.key_of(p + Eigen::Vector3f(0, 0, float(robot.body_height_m))).z;
  for (const Offset& o : offsets_)
    for (int z = z_lo; z <= z_hi; ++z)
      if (view.is_occupied({base.x + o.dx, base.y + o.dy, z})) return o.dist_m;
  return max_radius_m_;
}

}  // namespace storey::core::plan
