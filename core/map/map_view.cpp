#include "core/map/map_view.hpp"

#include <algorithm>
#include <cmath>

#include <algorithm>
#include <limits>

#include "core/map/point_plane.hpp"
#include "core/map/voxel_ray.hpp"

namespace storey::core::map {

namespace {
int16_t occ_threshold(const MapOptions& o) {
  return int16_t(std::lround(o.log_odds_occupied * kLogOddsScale));
}
Occupancy occupancy_of(const Cell* c, int16_t occ) {
  if (!c || !(c->flags & Cell::kObserved)) return Occupancy::kUnknown;
  return c->log_odds > occ ? Occupancy::kOccupied : Occupancy::kFree;
}
}  // namespace

VoxelKey MapView::key_of(const Eigen::Vector3f& p) const {
  const double inv = 1.0 / opt_->voxel_size_m;
  return floor_key(p.x() * inv, p.y() * inv, p.z() * inv);
}

Eigen::Vector3f MapView::centre_of(const VoxelKey& k) const {
  const double s = opt_->voxel_size_m;
  return Eigen::Vector3f(float((k.x + 0.5) * s), float((k.y + 0.5) * s), float((k.z + 0.5) * s));
}

Occupancy MapView::occupancy(const VoxelKey& k) const {
  BlockReader& r = reader();
  return occupancy_of(r.cell(k), occ_threshold(*opt_));
}

bool MapView::is_support(const VoxelKey& k) const {
  BlockReader& r = reader();
  const int16_t occ = occ_threshold(*opt_);
  if (occupancy_of(r.cell(k), occ) != Occupancy::kOccupied) return false;
  return occupancy_of(r.cell({k.x, k.y, k.z + 1}), occ) != Occupancy::kOccupied;
}

TravState MapView::state(const VoxelKey& k) const {
  BlockReader& r = reader();
  const Cell* c = r.cell(k);
  return c ? c->state : TravState::kNone;
}

bool MapView::is_reachable(const VoxelKey& k) const {
  BlockReader& r = reader();
  const Cell* c = r.cell(k);
  return c && (c->flags & Cell::kReachable);
}

uint32_t MapView::point_count(const VoxelKey& k) const {
  BlockReader& r = reader();
  const VoxelStats* s = r.stats(k);
  return s ? s->count : 0;
}

bool MapView::is_step_edge(const VoxelKey& k) const {
  BlockReader& r = reader();
  if (occupancy_of(r.cell(k), occ_threshold(*opt_)) != Occupancy::kOccupied) return false;
  const VoxelStats* s = r.stats(k);
  return s && (s->shape & VoxelStats::kStepEdge);
}

std::optional<Eigen::Vector2f> MapView::riser_normal(const VoxelKey& k) const {
  BlockReader& r = reader();
  if (occupancy_of(r.cell(k), occ_threshold(*opt_)) != Occupancy::kOccupied) return std::nullopt;
  const VoxelStats* s = r.stats(k);
  if (!s || !(s->shape & VoxelStats::kStepEdge)) return std::nullopt;
  const VoxelKey kb{k.x, k.y, k.z - 1};
  const bool below = opt_->pool_short_risers &&
                     occupancy_of(r.cell(kb), occ_threshold(*opt_)) == Occupancy::kOccupied;
  const Eigen::Vector2d n =
      riser_plane(*s, below ? r.stats(kb) : nullptr, opt_->voxel_size_m).normal.head<2>();
  if (n.norm() < 1e-6) return std::nullopt;
  return n.normalized().cast<float>();
}

float MapView::cost(const VoxelKey& k) const {
  BlockReader& r = reader();
  const VoxelStats* s = r.stats(k);
  return s ? s->cost : 0.0f;
}

std::optional<float> MapView::surface_height_m(const VoxelKey& k) const {
  BlockReader& r = reader();
  if (occupancy_of(r.cell(k), occ_threshold(*opt_)) != Occupancy::kOccupied) return std::nullopt;
  const VoxelStats* s = r.stats(k);
  const float centre = float((k.z + 0.5) * opt_->voxel_size_m);
  return centre + surface_offset(s, float(opt_->voxel_size_m));
}

std::optional<SurfacePoint> MapView::support_surface_near(const Eigen::Vector3f& p,
                                                          double window_m) const {
  BlockReader& r = reader();
  const int16_t occ = occ_threshold(*opt_);
  const double s = opt_->voxel_size_m;
  const VoxelKey c = key_of(p);
  const int32_t z_lo = int32_t(std::floor((p.z() - window_m) / s)) - 1;
  const int32_t z_hi = int32_t(std::floor((p.z() + window_m) / s)) + 1;
  std::optional<SurfacePoint> best;
  float best_d = std::numeric_limits<float>::infinity();
  bool above_occupied = occupancy_of(r.cell({c.x, c.y, z_hi + 1}), occ) == Occupancy::kOccupied;
  for (int32_t z = z_hi; z >= z_lo; --z) {  // top-down so "voxel above" is known
    const VoxelKey k{c.x, c.y, z};
    const Cell* cell = r.cell(k);
    const bool occupied = occupancy_of(cell, occ) == Occupancy::kOccupied;
    if (occupied && !above_occupied) {
      const VoxelStats* st = cell->stats == Cell::kNoStats ? nullptr : r.stats(k);
      const float h = float((z + 0.5) * s) + surface_offset(st, float(s));
      const float d = std::abs(h - p.z());
      if (d <= window_m && d < best_d) {
        best_d = d;
        best = SurfacePoint{k, h, cell->state, bool(cell->flags & Cell::kReachable)};
      }
    }
    above_occupied = occupied;
  }
  return best;
}

Occupancy MapView::probe(const Eigen::Vector3f& from, const Eigen::Vector3f& to,
                         VoxelKey* hit) const {
  BlockReader& r = reader();
  const int16_t occ = occ_threshold(*opt_);
  const double inv = 1.0 / opt_->voxel_size_m;
  const VoxelKey start = key_of(from);
  Occupancy result = Occupancy::kFree;
  auto visit = [&](const VoxelKey& k) {
    if (k == start) return true;
    const Occupancy o = occupancy_of(r.cell(k), occ);
    if (o == Occupancy::kFree) return true;
    result = o;
    if (hit) *hit = k;
    return false;
  };
  walk_ray(from.x() * inv, from.y() * inv, from.z() * inv, to.x() * inv, to.y() * inv, to.z() * inv,
           visit);
  if (result == Occupancy::kFree) {  // walk_ray stops before the end voxel: check it too
    const VoxelKey e = key_of(to);
    if (!(e == start)) {
      const Occupancy o = occupancy_of(r.cell(e), occ);
      if (o != Occupancy::kFree) {
        result = o;
        if (hit) *hit = e;
      }
    }
  }
  return result;
}

std::optional<VoxelKey> MapView::first_occupied(const Eigen::Vector3f& from,
                                                const Eigen::Vector3f& to) const {
  BlockReader& r = reader();
  const int16_t occ = occ_threshold(*opt_);
  const double inv = 1.0 / opt_->voxel_size_m;
  const VoxelKey start = key_of(from);
  std::optional<VoxelKey> found;
  auto visit = [&](const VoxelKey& k) {
    if (k == start) return true;
    if (occupancy_of(r.cell(k), occ) == Occupancy::kOccupied) {
      found = k;
      return false;
    }
    return true;
  };
  walk_ray(from.x() * inv, from.y() * inv, from.z() * inv, to.x() * inv, to.y() * inv, to.z() * inv,
           visit);
  if (!found) {
    const VoxelKey e = key_of(to);
    if (!(e == start) && occupancy_of(r.cell(e), occ) == Occupancy::kOccupied) found = e;
  }
  return found;
}

bool MapView::is_segment_free(const Eigen::Vector3f& from, const Eigen::Vector3f& to,
                              bool unknown_is_free) const {
  if (unknown_is_free) return !first_occupied(from, to).has_value();
  return probe(from, to) == Occupancy::kFree;
}

bool MapView::is_free_above(const VoxelKey& k, double height_m, bool unknown_is_free) const {
  BlockReader& r = reader();
  const int16_t occ = occ_threshold(*opt_);
  const int n = int(std::ceil(height_m / opt_->voxel_size_m - 1e-6));
  for (int i = 1; i <= n; ++i) {
    const Occupancy o = occupancy_of(r.cell({k.x, k.y, k.z + i}), occ);
    if (o == Occupancy::kOccupied) return false;
    if (o == Occupancy::kUnknown && !unknown_is_free) return false;
  }
  return true;
}

size_t MapView::occupied_in_box(const Eigen::Vector3f& centre, const Eigen::Vector3f& half,
                                std::vector<Eigen::Vector3f>& out) const {
  BlockReader& r = reader();
  const int16_t occ = occ_threshold(*opt_);
  const VoxelKey lo = key_of(centre - half), hi = key_of(centre + half);
  const size_t before = out.size();
  for (int32_t x = lo.x; x <= hi.x; ++x)
    for (int32_t y = lo.y; y <= hi.y; ++y)
      for (int32_t z = lo.z; z <= hi.z; ++z)
        if (occupancy_of(r.cell({x, y, z}), occ) == Occupancy::kOccupied)
          out.push_back(centre_of({x, y, z}));
  return out.size() - before;
}

size_t MapView::occupied_extents_in_box(const Eigen::Vector3f& centre, const Eigen::Vector3f& half,
                                        std::vector<VoxelExtent>& out) const {
  BlockReader& r = reader();
  const int16_t occ = occ_threshold(*opt_);
  const VoxelKey lo = key_of(centre - half), hi = key_of(centre + half);
  const float hs = float(0.5 * opt_->voxel_size_m);
  const size_t before = out.size();
  for (int32_t x = lo.x; x <= hi.x; ++x)
    for (int32_t y = lo.y; y <= hi.y; ++y)
      for (int32_t z = lo.z; z <= hi.z; ++z) {
        const VoxelKey k{x, y, z};
        if (occupancy_of(r.cell(k), occ) != Occupancy::kOccupied) continue;
        VoxelExtent e;
        e.centre_m = centre_of(k);
        e.half_m = Eigen::Vector3f::Constant(hs);
        e.surface_z_m = e.centre_m.z();
        const VoxelStats* st = r.stats(k);
        e.surface_z_m += surface_offset(st, float(opt_->voxel_size_m));
        if (st && st->count >= uint32_t(std::max(1, opt_->n_min))) {
          const float var[3] = {st->m2[0], st->m2[3], st->m2[5]};  // xx, yy, zz scatter sums
          for (int a = 0; a < 3; ++a) {
            const float sd = std::sqrt(std::max(0.0f, var[a] / float(st->count)));
            const float lo_a = std::max(-hs, st->mean[a] - 2.0f * sd - 0.01f);
            const float hi_a = std::min(hs, st->mean[a] + 2.0f * sd + 0.01f);
            if (!(hi_a > lo_a)) continue;  // degenerate: keep the whole voxel on this axis
            e.centre_m[a] += 0.5f * (lo_a + hi_a);
            e.half_m[a] = 0.5f * (hi_a - lo_a);
          }
        }
        out.push_back(e);
      }
  return out.size() - before;
}

}  // namespace storey::core::map
