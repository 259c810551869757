#include "core/map/traversability_map.hpp"

#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>

#include <Eigen/LU>

#include "core/map/point_plane.hpp"
#include "core/map/voxel_ray.hpp"

namespace storey::core::map {

namespace {
int16_t quantise(float log_odds) {
  const float q = std::round(log_odds * kLogOddsScale);
  return int16_t(std::clamp(q, -32000.0f, 32000.0f));
}
int voxels_ceil(double metres, double voxel) {
  return int(std::ceil(metres / voxel - 1e-9));
}
void require(bool ok, const char* what) {
  if (!ok) throw std::invalid_argument(std::string("MapOptions: ") + what);
}
}  // namespace

TraversabilityMap::TraversabilityMap(const MapOptions& o, const RobotModel& r)
    : opt_(o), robot_(r) {
  require(std::isfinite(o.voxel_size_m) && o.voxel_size_m >= 0.01 && o.voxel_size_m <= 2.0,
          "voxel_size_m must be in [0.01, 2] m");
  require(o.max_range_m > o.min_range_m && o.min_range_m >= 0,
          "need 0 <= min_range_m < max_range_m");
  require(o.log_odds_hit > 0 && o.log_odds_miss < 0, "log_odds_hit > 0 and log_odds_miss < 0");
  require(o.log_odds_min < o.log_odds_occupied && o.log_odds_occupied < o.log_odds_max,
          "need log_odds_min < log_odds_occupied < log_odds_max");
  require(o.log_odds_min > -30 && o.log_odds_max < 30, "log-odds clamps must be within +-30");
  require(o.n_min >= 1 && o.n_ref >= 1, "n_min and n_ref must be >= 1");
  require(o.neighbourhood_radius_m >= 0 && o.collision_radius_m >= 0, "radii must be >= 0");
  require(r.max_slope_rad > 0 && r.step_height_m >= 0 && r.body_height_m > 0,
          "RobotModel: max_slope_rad > 0, step_height_m >= 0, body_height_m > 0");
  hit_q_ = quantise(o.log_odds_hit);
  miss_q_ = quantise(o.log_odds_miss);
  min_q_ = quantise(o.log_odds_min);
  max_q_ = quantise(o.log_odds_max);
  occ_q_ = quantise(o.log_odds_occupied);
  const double s = o.voxel_size_m;
  r_agg_ = voxels_ceil(o.neighbourhood_radius_m, s);
  r_col_ = voxels_ceil(o.collision_radius_m, s);
  dz_step_ = voxels_ceil(r.step_height_m, s);
  h_clear_ = voxels_ceil(r.body_height_m + r.body_margin_m, s);
  dz_agg_ = voxels_ceil(o.neighbourhood_dz_m, s) + 1;
}

VoxelBlock* TraversabilityMap::wblock(const VoxelKey& k, bool create) {
  const uint64_t bk = block_key_of(k);
  if (wblock_ && bk == wkey_) return wblock_;
  VoxelBlock* b =
      store_.find_mutable(bk, k.x >> kBlockBits, k.y >> kBlockBits, k.z >> kBlockBits, create);
  if (!b) return nullptr;
  if (b->scan_id != scan_id_) {  // first write in this scan: the de-dup bits are stale
    std::memset(b->touched, 0, sizeof(b->touched));
    b->scan_id = scan_id_;
  }
  wkey_ = bk;
  wblock_ = b;
  return b;
}

void TraversabilityMap::mark_changed(const VoxelKey& k, Cell& c) {
  if (c.flags & Cell::kChanged) return;
  c.flags |= Cell::kChanged;
  changed_.push_back(k);
}

InsertStats TraversabilityMap::insert_scan(const Eigen::Vector3f& o,
                                           std::span<const Eigen::Vector3f> pts) {
  InsertStats st;
  st.points = uint32_t(pts.size());
  const float lim = float(opt_.world_limit_m);
  auto in_world = [lim](const Eigen::Vector3f& p) {
    return std::isfinite(p.x()) && std::isfinite(p.y()) && std::isfinite(p.z()) &&
           std::abs(p.x()) <= lim && std::abs(p.y()) <= lim && std::abs(p.z()) <= lim;
  };
  if (!in_world(o)) {
    st.origin_invalid = true;
    st.dropped_invalid = st.points;
    return st;
  }
  // New scan: fresh de-dup bits. The cached write block's bits belong to the previous scan, so
  // the cache is dropped here (wblock() resets a block's bits on its first fetch in a scan).
  if (++scan_id_ == 0) scan_id_ = 1;
  wblock_ = nullptr;
  ++version_;

  const double s = opt_.voxel_size_m, inv = 1.0 / s;
  const float min2 = float(opt_.min_range_m * opt_.min_range_m);
  const float max2 = float(opt_.max_range_m * opt_.max_range_m);
  constexpr uint32_t kTruncated = 0x80000000u;
  ray_points_.clear();

  // Pass 1: endpoints (hits first so that a voxel both hit and crossed this scan counts as hit).
  for (uint32_t i = 0; i < pts.size(); ++i) {
    const Eigen::Vector3f& p = pts[i];
    if (!in_world(p)) {
      ++st.dropped_invalid;
      continue;
    }
    const float r2 = (p - o).squaredNorm();
    if (r2 < min2) {
      ++st.dropped_min_range;
      continue;
    }
    if (r2 > max2) {
      ++st.truncated;
      ray_points_.push_back(i | kTruncated);
      continue;
    }
    ++st.hits;
    const VoxelKey k = floor_key(p.x() * inv, p.y() * inv, p.z() * inv);
    VoxelBlock* b = wblock(k, true);
    const int idx = cell_index(k);
    Cell& c = b->cells[idx];
    if (!b->test_and_set_touched(idx)) {  // first hit of this voxel in this scan
      const bool was_occ = occupied(&c);
      c.flags |= Cell::kObserved;
      c.log_odds = int16_t(std::min<int>(c.log_odds + hit_q_, max_q_));
      if (!was_occ && occupied(&c)) {
        ++occupied_count_;
        mark_changed(k, c);
      }
      ray_points_.push_back(i);
    }
    if (c.stats == Cell::kNoStats) c.stats = b->alloc_stats();
    VoxelStats& vs = b->stats[c.stats];
    vs.add(float(p.x() - (k.x + 0.5) * s), float(p.y() - (k.y + 0.5) * s),
           float(p.z() - (k.z + 0.5) * s));
    if (opt_.floor_seen_from_above) {  // per point: only when used
      const float run = std::max(std::hypot(p.x() - o.x(), p.y() - o.y()), 1e-3f);
      const int rise =
          int(std::lround(std::clamp(100.0f * (p.z() - o.z()) / run, -127.0f, 127.0f)));
      // Re-judged when it drops below 0.02 (seen from above whatever the surface's slope) or by
      // 0.05 above that (a slope's threshold passed); below 0.02 nothing changes any more. (Only
      // on doubling N(v), a floor grazed from the flight below and then from the top of the
      // flight stayed S_untrav: the teaching building's upper floor was left.)
      if (rise < vs.min_rise) {
        if (vs.min_rise >= 2 && (rise < 2 || rise <= vs.min_rise - 5)) mark_changed(k, c);
        vs.min_rise = int8_t(rise);
      }
    }
    // Re-evaluate tau(v) when N(v) reaches N_min or doubles since the last evaluation: the
    // statistics of a well-observed voxel barely move, so re-running Eq. 1-3 on every point
    // would cost without changing the state.
    if (vs.count == uint32_t(opt_.n_min) || vs.count >= 2 * vs.count_eval) mark_changed(k, c);
  }

  const double ox = o.x() * inv, oy = o.y() * inv, oz = o.z() * inv;
  Eigen::Vector3d ray_dir;  // unit, world frame, set per ray below
  const Eigen::Vector3d od = o.cast<double>();
  // MapOptions::miss_needs_crossing: whether the ray crosses, inside voxel k, the plane through
  // `mean` (world) with normal `nrm`.
  auto crosses_in_voxel = [&](const VoxelKey& k, const Eigen::Vector3d& mean,
                              const Eigen::Vector3d& nrm) {
    const int32_t kk[3] = {k.x, k.y, k.z};
    double t0 = 0, t1 = std::numeric_limits<double>::infinity();  // the ray inside the voxel
    for (int a = 0; a < 3; ++a) {
      if (std::abs(ray_dir[a]) < 1e-12) continue;
      double ta = (kk[a] * s - od[a]) / ray_dir[a], tb = ((kk[a] + 1) * s - od[a]) / ray_dir[a];
      if (ta > tb) std::swap(ta, tb);
      t0 = std::max(t0, ta), t1 = std::min(t1, tb);
    }
    if (!(t1 >= t0)) return true;  // numerically at a corner: counted, as without the option
    return nrm.dot(od + t0 * ray_dir - mean) * nrm.dot(od + t1 * ray_dir - mean) <= 0.0;
  };
  // Under 3 points of its own (a wall's far part, seen once or twice): the plane of its points
  // pooled with its 26 neighbours' (at least 6 points in all); none or no clear plane: counted.
  auto crosses_pooled_plane = [&](const VoxelKey& k, const VoxelStats& own) {
    double n = 0;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    Eigen::Matrix3d m2 = Eigen::Matrix3d::Zero(), outer = Eigen::Matrix3d::Zero();
    for (int32_t dx = -1; dx <= 1; ++dx)
      for (int32_t dy = -1; dy <= 1; ++dy)
        for (int32_t dz = -1; dz <= 1; ++dz) {
          const VoxelKey q{k.x + dx, k.y + dy, k.z + dz};
          const VoxelStats* st = rstats(q);
          if (!st || st->count == 0) continue;
          const Eigen::Vector3d m((q.x + 0.5) * s + st->mean[0], (q.y + 0.5) * s + st->mean[1],
                                  (q.z + 0.5) * s + st->mean[2]);
          n += st->count;
          sum += st->count * m;
          m2 += scatter(*st);
          outer += st->count * m * m.transpose();
        }
    if (n < 6) return true;
    const Eigen::Vector3d mean = sum / n;
    const PointPlane pl = plane_of_scatter(m2 + outer - n * mean * mean.transpose(), n);
    if (!clear_plane(pl)) return true;
    // Its own points on that plane (not a stray return above a floor, which a ray passing over
    // the floor would otherwise never clear).
    if (own.count == 0) return true;
    const Eigen::Vector3d m((k.x + 0.5) * s + own.mean[0], (k.y + 0.5) * s + own.mean[1],
                            (k.z + 0.5) * s + own.mean[2]);
    if (std::abs(pl.normal.dot(m - mean)) > std::max(0.02, 3.0 * std::sqrt(pl.eigenvalues[0])))
      return true;
    return crosses_in_voxel(k, mean, pl.normal);
  };
  // A ray crossing an occupied voxel only counts as a miss if it passes through the voxel's
  // point distribution (Mahalanobis distance <= 3 from the points' Gaussian, as in NDT-OM,
  // Saarinen et al. 2013). Otherwise grazing rays over a floor would erode the floor voxels,
  // whose points fill only the bottom of the voxel. With miss_needs_crossing, points on a plane
  // count a ray only if it crosses the plane in the voxel: rays down a corridor pass within the
  // points' spread in front of its walls without meeting them.
  auto ray_meets_points = [&](const VoxelKey& k, const VoxelStats& vs) {
    if (vs.count < 3) return !opt_.miss_needs_crossing || crosses_pooled_plane(k, vs);
    const Eigen::Vector3d mean((k.x + 0.5) * s + vs.mean[0], (k.y + 0.5) * s + vs.mean[1],
                               (k.z + 0.5) * s + vs.mean[2]);
    const Eigen::Vector3d rel = mean - od;
    const Eigen::Vector3d delta = rel - ray_dir * rel.dot(ray_dir);  // mean -> nearest ray point
    const double n = vs.count, reg = 0.0025 * s * s;  // (5% of a voxel)^2 regulariser
    Eigen::Matrix3d cov;
    cov << vs.m2[0] / n + reg, vs.m2[1] / n, vs.m2[2] / n, vs.m2[1] / n, vs.m2[3] / n + reg,
        vs.m2[4] / n, vs.m2[2] / n, vs.m2[4] / n, vs.m2[5] / n + reg;
    if (delta.dot(cov.inverse() * delta) > 9.0) return false;  // closed-form 3x3 inverse
    if (!opt_.miss_needs_crossing) return true;
    const PointPlane pl = point_plane(vs);
    return !clear_plane(pl) || crosses_in_voxel(k, mean, pl.normal);
  };
  // Pass 2: free space along each de-duplicated ray.
  const int early_stop = opt_.ray_early_stop_voxels;
  int run = 0;  // consecutive voxels of the current ray already updated in this scan
  auto miss = [&](const VoxelKey& k) {
    VoxelBlock* b = wblock(k, true);
    const int idx = cell_index(k);
    if (b->test_and_set_touched(idx)) {  // already hit or missed in this scan
      return early_stop <= 0 || ++run < early_stop;
    }
    run = 0;
    Cell& c = b->cells[idx];
    const bool was_occ = occupied(&c);
    if (was_occ && c.stats != Cell::kNoStats && !ray_meets_points(k, b->stats[c.stats]))
      return true;  // grazes past the surface in this voxel: no evidence against it
    c.flags |= Cell::kObserved;
    c.log_odds = int16_t(std::max<int>(c.log_odds + miss_q_, min_q_));
    if (was_occ && !occupied(&c)) {
      --occupied_count_;
      mark_changed(k, c);
    }
    return true;
  };
  ray_dir = Eigen::Vector3d::UnitZ();
  miss(floor_key(ox, oy, oz));  // the sensor is in free space
  for (uint32_t e : ray_points_) {
    const bool truncated = e & kTruncated;
    const Eigen::Vector3f& p = pts[e & ~kTruncated];
    double ex = p.x() * inv, ey = p.y() * inv, ez = p.z() * inv;
    if (truncated) {  // clear up to max range, no endpoint
      const double f = opt_.max_range_m / double((p - o).norm());
      ex = ox + (ex - ox) * f;
      ey = oy + (ey - oy) * f;
      ez = oz + (ez - oz) * f;
    }
    ray_dir = Eigen::Vector3d(ex - ox, ey - oy, ez - oz).normalized();
    // Endpoint -> sensor: the voxels unique to this ray come first, the shared ones last.
    // Visits the endpoint voxel (already hit, or the max-range voxel of a truncated ray) and
    // stops before the sensor's voxel, which is cleared once per scan above.
    run = 0;
    st.voxels_walked += walk_ray(ex, ey, ez, ox, oy, oz, miss);
    ++st.rays_cast;
  }
  st.changed = uint32_t(changed_.size());
  return st;
}

std::shared_ptr<const MapSnapshot> TraversabilityMap::snapshot() {
  // Every block is now shared with the snapshot: the cached write pointer must not be used
  // for writing again (the next wblock() clones the block first).
  wblock_ = nullptr;
  reader_.invalidate();
  return std::make_shared<const MapSnapshot>(store_, opt_, robot_, version_, occupied_count_,
                                             trav_count_, reach_count_);
}

size_t TraversabilityMap::mem_usage() const {
  return sizeof(*this) + store_.mem_usage() + ray_points_.capacity() * sizeof(uint32_t) +
         (changed_.capacity() + dirty_.capacity() + orphans_.capacity() + grow_queue_.capacity()) *
             sizeof(VoxelKey) +
         reach_changed_.capacity() * sizeof(ReachChange) +
         orphan_queue_.capacity() * sizeof(orphan_queue_[0]);
}

}  // namespace storey::core::map
