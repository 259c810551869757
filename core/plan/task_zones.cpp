#include "core/plan/task_zones.hpp"

#include <algorithm>
#include <climits>
#include <cmath>
#include <limits>
#include <tuple>

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

void ObstacleClearance::operator()(const map::MapView& view,
                                   std::span<const Eigen::Vector3f> points,
                                   std::vector<double>& out) {
  const double v = view.voxel_size_m();
  if (v != built_for_voxel_m_) build(v);
  out.assign(points.size(), 0.0);
  const RobotModel& robot = view.robot();
  struct Key {
    int32_t x, y, z_lo, z_hi;
  };
  std::vector<Key> keys(points.size());
  order_.clear();
  for (uint32_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3f& p = points[i];
    if (!p.allFinite()) continue;  // 0, as the single-point query
    const map::VoxelKey base = view.key_of(p);
    keys[i] = {base.x, base.y,
               view.key_of(p + Eigen::Vector3f(0, 0, float(robot.step_height_m + v * 0.5))).z,
               view.key_of(p + Eigen::Vector3f(0, 0, float(robot.body_height_m))).z};
    order_.push_back(i);
  }
  // Points sorted by band; a group spans at most 64 layers, one column memo per group holding
  // the occupied layers of each column as a bit mask (points a few layers apart share it).
  std::stable_sort(order_.begin(), order_.end(), [&](uint32_t a, uint32_t b) {
    return std::tie(keys[a].z_lo, keys[a].z_hi) < std::tie(keys[b].z_lo, keys[b].z_hi);
  });
  const int32_t r = int32_t(std::ceil(max_radius_m_ / v));
  constexpr size_t kMaxMemo = size_t(1) << 22;  // 4 M columns (40 MB); beyond: point by point
  for (size_t b = 0; b < order_.size();) {
    const int32_t z0 = keys[order_[b]].z_lo;
    int32_t z1 = z0, x0 = INT32_MAX, x1 = INT32_MIN, y0 = INT32_MAX, y1 = INT32_MIN;
    size_t e = b;
    for (; e < order_.size() && keys[order_[e]].z_hi - z0 < 64; ++e) {
      const Key& k = keys[order_[e]];
      z1 = std::max(z1, k.z_hi);
      x0 = std::min(x0, k.x - r);
      x1 = std::max(x1, k.x + r);
      y0 = std::min(y0, k.y - r);
      y1 = std::max(y1, k.y + r);
    }
    if (e == b) {  // a band taller than 64 layers: on its own
      out[order_[b]] = (*this)(view, points[order_[b]]);
      ++b;
      continue;
    }
    const size_t w = size_t(x1 - x0 + 1), h = size_t(y1 - y0 + 1);
    if (w * h > kMaxMemo) {
      for (size_t j = b; j < e; ++j) out[order_[j]] = (*this)(view, points[order_[j]]);
      b = e;
      continue;
    }
    mask_.assign(w * h, 0);
    done_.assign(w * h, 0);
    for (size_t j = b; j < e; ++j) {
      const Key& k = keys[order_[j]];
      // Layers z_lo..z_hi of this point as bits relative to z0.
      const int n = k.z_hi - k.z_lo + 1;
      const uint64_t band =
          n <= 0 ? 0 : ((n >= 64 ? ~uint64_t(0) : (uint64_t(1) << n) - 1) << (k.z_lo - z0));
      double c = max_radius_m_;
      for (const Offset& o : offsets_) {
        const int32_t x = k.x + o.dx, y = k.y + o.dy;
        const size_t m = size_t(x - x0) + size_t(y - y0) * w;
        if (!done_[m]) {
          done_[m] = 1;
          uint64_t bits = 0;
          for (int32_t z = z0; z <= z1; ++z)
            if (view.is_occupied({x, y, z})) bits |= uint64_t(1) << (z - z0);
          mask_[m] = bits;
        }
        if (mask_[m] & band) {
          c = o.dist_m;
          break;
        }
      }
      out[order_[j]] = c;
    }
    b = e;
  }
}

}  // namespace storey::core::plan
