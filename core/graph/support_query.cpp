#include "core/graph/support_query.hpp"

#include <cmath>
#include <limits>

#include "core/map/voxel_ray.hpp"

namespace storey::core::graph {

using map::Cell;
using map::Occupancy;
using map::TravState;
using map::VoxelKey;

SupportQuery::SupportQuery(const map::MapView& view, const GraphOptions& opt)
    : view_(view), reader_(view.store()), opt_(opt) {
  occ_q_ = int16_t(std::lround(view.options().log_odds_occupied * map::kLogOddsScale));
  vs_ = float(view.voxel_size_m());
  inv_vs_ = 1.0f / vs_;
  const RobotModel& r = view.robot();
  step_ = float(r.step_height_m + opt.surface_tolerance_m);
  clear_ = float(r.body_height_m + r.body_margin_m);
  col_lo_ = float(r.step_height_m);
  lateral_m_ = float(0.5 * r.body_width_m + r.body_margin_m);
  tan_slope_ = float(std::tan(opt.max_edge_slope_rad));
}

int32_t SupportQuery::zkey(float z) const {
  return int32_t(std::floor(z * inv_vs_));
}

Occupancy SupportQuery::occupancy(const VoxelKey& k) {
  const Cell* c = cell(k);
  if (!c || !(c->flags & Cell::kObserved)) return Occupancy::kUnknown;
  return c->log_odds > occ_q_ ? Occupancy::kOccupied : Occupancy::kFree;
}

// MapOptions::floor_seen_from_above: S_untrav as not a top (nothing occupied above it here: seen
// only from below), or too few points for tau(v) and every ray that hit it rose.
bool SupportQuery::underside(const Cell& c, const map::VoxelStats* st) const {
  if (!st || !view_.options().floor_seen_from_above) return false;
  if (c.state == TravState::kUnobserved) return st->min_rise >= 2;
  return c.state == TravState::kUntraversable && (st->reasons & map::VoxelStats::kReasonNotTop);
}

std::optional<Support> SupportQuery::surface_near(float x, float y, float z, float window) {
  const int32_t cx = int32_t(std::floor(x * inv_vs_)), cy = int32_t(std::floor(y * inv_vs_));
  const int32_t z_lo = zkey(z - window) - 1, z_hi = zkey(z + window) + 1;
  std::optional<Support> best;
  float best_d = std::numeric_limits<float>::infinity();
  bool above = occupied(cell({cx, cy, z_hi + 1}));
  for (int32_t kz = z_hi; kz >= z_lo; --kz) {  // top-down so "voxel above" is known
    const VoxelKey k{cx, cy, kz};
    const Cell* c = cell(k);
    const bool occ = occupied(c);
    // (A slab's underside seen from below also has no occupied voxel right above it; it is
    // rejected by the body clearance, the slab's top lies within the body height.)
    if (occ && !above) {
      const map::VoxelStats* st = c->stats == Cell::kNoStats ? nullptr : reader_.stats(k);
      const float h = (float(kz) + 0.5f) * vs_ + map::surface_offset(st, vs_);
      const float d = std::abs(h - z);
      if (d <= window && d < best_d) {
        best_d = d;
        best = Support{Eigen::Vector3f(x, y, h),
                       k,
                       c->state,
                       bool(c->flags & Cell::kReachable),
                       st ? st->cost : 0.0f,
                       underside(*c, st)};
      }
    }
    above = occ;
  }
  return best;
}

namespace {
int rank(const Support& s) {
  if (s.reachable) return 3;
  switch (s.state) {
    case TravState::kTraversable:
      return 2;
    case TravState::kUnobserved:
      return 1;
    default:
      return 0;
  }
}
}  // namespace

std::optional<Support> SupportQuery::support_dilated(float x, float y, float z, float window) {
  std::optional<Support> best = surface_near(x, y, z, window);
  if (best && best->reachable) return best;
  int best_rank = best ? rank(*best) : -1;
  float best_d = best ? std::abs(best->p_m.z() - z) : 0.0f;
  for (int dx = -1; dx <= 1; ++dx)
    for (int dy = -1; dy <= 1; ++dy) {
      if (dx == 0 && dy == 0) continue;
      const std::optional<Support> s =
          surface_near(x + float(dx) * vs_, y + float(dy) * vs_, z, window);
      if (!s) continue;
      const int r = rank(*s);
      const float d = std::abs(s->p_m.z() - z);
      if (r > best_rank || (r == best_rank && d < best_d)) {
        best = s;
        best_rank = r;
        best_d = d;
      }
    }
  if (best) {
    best->p_m.x() = x;
    best->p_m.y() = y;
  }
  return best;
}

bool SupportQuery::body_clear(float x, float y, float h, const Eigen::Vector2f& lateral) {
  // Heights of occupied voxels by their points' mean (as R_col in the map, Eq. 3), so a stair
  // nose one step up that shares a voxel layer with the clearance band does not count.
  const int32_t z_lo = zkey(h + col_lo_) - 1, z_hi = zkey(h + clear_);
  for (int side = -1; side <= 1; ++side) {
    const float px = x + float(side) * lateral.x() * lateral_m_;
    const float py = y + float(side) * lateral.y() * lateral_m_;
    const int32_t cx = int32_t(std::floor(px * inv_vs_)), cy = int32_t(std::floor(py * inv_vs_));
    for (int32_t kz = z_lo; kz <= z_hi; ++kz) {
      const VoxelKey k{cx, cy, kz};
      const Cell* c = cell(k);
      if (!occupied(c)) continue;
      const map::VoxelStats* st = c->stats == Cell::kNoStats ? nullptr : reader_.stats(k);
      const float hv = (float(kz) + 0.5f) * vs_ + map::surface_offset(st, vs_);
      if (hv > h + col_lo_ && hv <= h + clear_) return false;
    }
  }
  return true;
}

bool SupportQuery::fall_risk(const Eigen::Vector3f& p) {
  int drops = 0;
  for (int i = 0; i < 8; ++i) {
    const float a = float(i) * float(M_PI) / 4.0f;
    const float x = p.x() + lateral_m_ * std::cos(a), y = p.y() + lateral_m_ * std::sin(a);
    if (surface_near(x, y, p.z(), step_)) continue;
    const int32_t cx = int32_t(std::floor(x * inv_vs_)), cy = int32_t(std::floor(y * inv_vs_));
    // Observed free at the surface level and one step below: nothing to stand on.
    const int32_t kz = zkey(p.z());
    if (free(cell({cx, cy, kz})) && free(cell({cx, cy, zkey(p.z() - step_)}))) ++drops;
  }
  return drops >= 2;
}

map::Occupancy SupportQuery::walk(const Eigen::Vector3f& from, const Eigen::Vector3f& to,
                                  bool stop_at_unknown, float* free_m) {
  const map::VoxelKey start{int32_t(std::floor(from.x() * inv_vs_)),
                            int32_t(std::floor(from.y() * inv_vs_)),
                            int32_t(std::floor(from.z() * inv_vs_))};
  Occupancy result = Occupancy::kFree;
  uint32_t steps = 0;
  auto visit = [&](const VoxelKey& k) {
    if (k == start) return true;
    const Occupancy o = occupancy(k);
    if (o == Occupancy::kFree || (o == Occupancy::kUnknown && !stop_at_unknown)) {
      ++steps;
      return true;
    }
    result = o;
    return false;
  };
  const uint32_t n = map::walk_ray(from.x() * inv_vs_, from.y() * inv_vs_, from.z() * inv_vs_,
                                   to.x() * inv_vs_, to.y() * inv_vs_, to.z() * inv_vs_, visit);
  if (result == Occupancy::kFree) {  // walk_ray stops before the end voxel
    const VoxelKey e{int32_t(std::floor(to.x() * inv_vs_)), int32_t(std::floor(to.y() * inv_vs_)),
                     int32_t(std::floor(to.z() * inv_vs_))};
    if (!(e == start)) visit(e);
  }
  if (free_m) {
    const float len = (to - from).norm();
    *free_m = n ? len * float(steps) / float(n + 1) : 0.0f;
  }
  return result;
}

bool SupportQuery::hole_in_surface(const VoxelKey& k) {
  auto occ = [&](int32_t dx, int32_t dy, int32_t dz) {
    return occupancy({k.x + dx, k.y + dy, k.z + dz}) == Occupancy::kOccupied;
  };
  // Surface on both sides along one axis: a gap in a sheet. One side only is an edge (the top
  // of a riser with the tread beyond it unseen: a stair's frontier, kept open).
  return (occ(1, 0, 0) && occ(-1, 0, 0)) || (occ(0, 1, 0) && occ(0, -1, 0)) ||
         (occ(0, 0, 1) && occ(0, 0, -1));
}

SupportQuery::ProbeSegment SupportQuery::probe_segment(const Eigen::Vector3f& from,
                                                       const Eigen::Vector3f& to, int need_free,
                                                       int* free_total, int* unknown_run) {
  const VoxelKey start{int32_t(std::floor(from.x() * inv_vs_)),
                       int32_t(std::floor(from.y() * inv_vs_)), zkey(from.z())};
  ProbeSegment r;
  VoxelKey prev = start;
  auto visit = [&](const VoxelKey& k) {
    if (k == start) return true;
    const VoxelKey before = prev;
    prev = k;
    switch (occupancy(k)) {
      case Occupancy::kOccupied:
        r.hit = true;
        r.hit_key = k;
        return false;
      case Occupancy::kFree:
        ++*free_total;
        *unknown_run = 0;  // an enclosed hole in known space, not an unknown region
        return true;
      case Occupancy::kUnknown:
        if (*free_total < need_free) {  // did not start in known free space
          r.closed = true;
          return false;
        }
        // Entering unknown space through a gap in a surface (a wall seen only at grazing
        // angles keeps voxel-sized holes, unknown or carved free; behind them lies the wall's or
        // a ramp's solid, never observable): closed, else a corridor's walls made frontiers
        // that no view resolves.
        if (*unknown_run == 0 && opt_.close_probes_at_holes &&
            (hole_in_surface(k) || hole_in_surface(before))) {
          r.closed = r.hole = true;
          return false;
        }
        if (*unknown_run == 0) r.run_start = k;
        ++*unknown_run;
        return true;
    }
    return false;
  };
  map::walk_ray(from.x() * inv_vs_, from.y() * inv_vs_, from.z() * inv_vs_, to.x() * inv_vs_,
                to.y() * inv_vs_, to.z() * inv_vs_, visit);
  return r;
}

bool SupportQuery::probe_open(const Eigen::Vector3f& from, const Eigen::Vector3f& to,
                              float min_free_m, float min_unknown_m) {
  const Eigen::Vector3f d = to - from;
  const float len = d.norm();
  if (len <= 0) return false;
  // Voxels visited per metre along the probe (6-connected walk: |dx| + |dy| + |dz| voxels).
  const float per_m = (std::abs(d.x()) + std::abs(d.y()) + std::abs(d.z())) * inv_vs_ / len;
  const int need_free = int(std::ceil(min_free_m * per_m));
  const int need_unknown = std::max(1, int(std::ceil(min_unknown_m * per_m)));
  int free_total = 0, unknown_run = 0;
  const ProbeSegment seg = probe_segment(from, to, need_free, &free_total, &unknown_run);
  // Open: the probe ends inside an unknown region (at least min_unknown_m of it) that it
  // entered from known free space, with no obstacle on the way.
  return !seg.hit && !seg.closed && unknown_run >= need_unknown;
}

namespace {
constexpr float kStairGrade = 0.466f;  // tan(25 deg)
// Steps at stair grade before a probe counts as climbing a flight: one is a curb, or the low end
// of a ramp's side rising under a step (test_ramp: C_exp frontiers along the ramp no view
// resolved).
constexpr int kStairSteps = 2;
}  // namespace

bool SupportQuery::wall_face(const Support& top, const Eigen::Vector2f& dir) {
  const float x = (float(top.key.x) + 0.5f) * vs_, y = (float(top.key.y) + 0.5f) * vs_;
  for (int d = 1; d <= 2; ++d) {
    const int32_t kx = int32_t(std::floor((x + dir.x() * vs_ * float(d)) * inv_vs_));
    const int32_t ky = int32_t(std::floor((y + dir.y() * vs_ * float(d)) * inv_vs_));
    if (occupied(cell({kx, ky, top.key.z + 1})) && occupied(cell({kx, ky, top.key.z + 2})))
      return true;
  }
  return false;
}

bool SupportQuery::probe_open_climbing(const Eigen::Vector3f& foot, const Eigen::Vector2f& dir,
                                       float length_m, float height_m, float min_free_m,
                                       float min_unknown_m, bool* climbed, bool* leaves_reach,
                                       bool* blocked, ProbeWhy* why) {
  constexpr int kMaxClimbs = 24;
  if (climbed) *climbed = false;
  if (blocked) *blocked = false;
  if (leaves_reach) *leaves_reach = false;
  // Horizontal probe: |dx| + |dy| voxels per metre (6-connected walk).
  const float per_m = (std::abs(dir.x()) + std::abs(dir.y())) * inv_vs_;
  const int need_free = int(std::ceil(min_free_m * per_m));
  const int need_unknown = std::max(1, int(std::ceil(min_unknown_m * per_m)));
  const float max_rise = 2.0f * step_;
  float s0 = 0, s_climb = 0, zc = foot.z();
  int free_total = 0, unknown_run = 0, stair_steps = 0;
  // The probe reaches length_m past its last climb: it follows a flight to its top (a node low
  // on a 5 m flight sees only known treads within 3 m).
  // (GraphOptions::climb_frontiers; else length_m from the node).
  auto reach = [&] { return (opt_.climb_frontiers ? s_climb : 0.0f) + length_m; };
  // GraphOptions::ramp_frontiers: an open probe whose support rose a step height in climbs
  // flatter than a stair's (kStairGrade) climbed a ramp (a curb is no ramp).
  float gradual = 0;
  auto open_end = [&](bool open) {
    if (open && climbed && opt_.ramp_frontiers && gradual >= step_) *climbed = true;
    return open;
  };
  auto centre = [&](const VoxelKey& k) {
    return Eigen::Vector3f((float(k.x) + 0.5f) * vs_, (float(k.y) + 0.5f) * vs_,
                           (float(k.z) + 0.5f) * vs_);
  };
  auto opened_by = [&](OpenBy by, const Eigen::Vector3f& at) {
    if (why) *why = {by, at};
  };
  if (why) *why = {};
  for (int climb = 0; climb <= kMaxClimbs && s0 < reach(); ++climb) {
    const float s_end = reach();
    const Eigen::Vector3f from(foot.x() + dir.x() * s0, foot.y() + dir.y() * s0, zc + height_m);
    const Eigen::Vector3f to(foot.x() + dir.x() * s_end, foot.y() + dir.y() * s_end, zc + height_m);
    const ProbeSegment seg = probe_segment(from, to, need_free, &free_total, &unknown_run);
    if (blocked) *blocked = seg.hole;
    if (seg.closed) return false;
    if (!seg.hit) {
      if (unknown_run >= need_unknown) opened_by(OpenBy::kUnknownRun, centre(seg.run_start));
      return open_end(unknown_run >= need_unknown);
    }
    const VoxelKey& hit = seg.hit_key;
    const float hx = (float(hit.x) + 0.5f) * vs_, hy = (float(hit.y) + 0.5f) * vs_;
    const float s_hit = (Eigen::Vector2f(hx, hy) - foot.head<2>()).dot(dir);
    const std::optional<Support> top = surface_near(hx, hy, zc + 0.5f * max_rise, 0.5f * max_rise);
    const float rise = top ? top->p_m.z() - zc : 0.0f;
    if (top && rise > 0.5f * vs_ && rise <= max_rise &&
        rise <= step_ + tan_slope_ * std::max(0.0f, s_hit - s_climb) &&
        !(opt_.close_probes_at_wall_faces && wall_face(*top, dir))) {
      // A step up onto support the LiDAR saw only edge-on (a tread seen from below: its
      // riser's top, N(v) < N_min): terrain not yet observed, what the probe looks for.
      // A stair's step: steeper than tan(25 deg) since the last climb (flights ~30 deg; a ramp,
      // 5-20 deg in buildings, keeps the ground ahead in the LiDAR's view: judged as level).
      const bool stair = rise >= kStairGrade * std::max(s_hit - s_climb, vs_);
      if (stair && ++stair_steps >= kStairSteps && climbed) *climbed = true;
      if (!stair) gradual += rise;
      if (top->state == TravState::kUnobserved) {
        if (free_total >= need_free) opened_by(OpenBy::kUnobservedStep, top->p_m);
        return open_end(free_total >= need_free);
      }
      if (leaves_reach && stair_steps >= kStairSteps && !top->reachable) *leaves_reach = true;
      zc = top->p_m.z();
      s_climb = s_hit;
      s0 = std::max(s_hit, s0 + 0.5f * vs_);
      unknown_run = 0;
      continue;
    }
    // Unknown right above the obstacle (within two voxels): terrain beyond a step not yet seen.
    for (int32_t dz = 1; dz <= 2; ++dz) {
      const Occupancy o = occupancy({hit.x, hit.y, hit.z + dz});
      if (o == Occupancy::kUnknown) {
        if (free_total >= need_free)
          opened_by(OpenBy::kUnknownOverObstacle, centre({hit.x, hit.y, hit.z + dz}));
        return open_end(free_total >= need_free);
      }
      if (o == Occupancy::kFree) break;
    }
    if (blocked) *blocked = true;
    return false;
  }
  return false;
}

Reject SupportQuery::classify_node(const Support& s, bool* confirmed) {
  *confirmed = false;
  if (s.state == TravState::kUntraversable || s.state == TravState::kNone)
    return Reject::kUntraversable;
  if (!body_clear(s.p_m.x(), s.p_m.y(), s.p_m.z(), Eigen::Vector2f(1, 0)) ||
      !body_clear(s.p_m.x(), s.p_m.y(), s.p_m.z(), Eigen::Vector2f(0, 1)))
    return Reject::kCollision;
  if (s.reachable) {  // C_reach already excludes R_col and R_fall (Eq. 3)
    *confirmed = true;
    return Reject::kNone;
  }
  // Tentative: the whole body footprint (half length + margin around the node) is clear.
  const RobotModel& r = view_.robot();
  const float reach = float(0.5 * r.body_length_m + r.body_margin_m) - lateral_m_;
  for (int k = 0; k < 8; ++k) {
    const float a = float(k) * float(M_PI) / 4.0f;
    const Eigen::Vector2f dir(std::cos(a), std::sin(a));
    if (!body_clear(s.p_m.x() + reach * dir.x(), s.p_m.y() + reach * dir.y(), s.p_m.z(),
                    Eigen::Vector2f(-dir.y(), dir.x())))
      return Reject::kCollision;
  }
  // Tentative support must have been seen from above: some voxel over it (before anything
  // occupied) was crossed by a ray. The underside of a slab, seen only from below, has unknown
  // space over it until the floor above is observed.
  // Rays graze sparse ground from afar: the layer right above the surface in the 8 neighbour
  // columns counts too (inside a slab it is unknown as well).
  bool seen = false;
  for (int dx = -1; dx <= 1 && !seen; ++dx)
    for (int dy = -1; dy <= 1 && !seen; ++dy)
      seen = free(cell({s.key.x + dx, s.key.y + dy, s.key.z + 1}));
  for (int dz = 2; dz <= 2 && !seen; ++dz) {
    const Cell* c = cell({s.key.x, s.key.y, s.key.z + dz});
    if (occupied(c)) break;
    seen = free(c);
  }
  if (!seen) return Reject::kNoSupport;
  // Tentative: collision-free and free of fall risk over under-observed ground (Sec. III-B).
  if (fall_risk(s.p_m)) return Reject::kFallRisk;
  return opt_.use_tentative ? Reject::kNone : Reject::kNotReachable;
}

EdgeCheck SupportQuery::check_edge(const Eigen::Vector3f& a, const Eigen::Vector3f& b) {
  EdgeCheck out;
  const Eigen::Vector2f d(b.x() - a.x(), b.y() - a.y());
  const float L = d.norm();
  const float dz = b.z() - a.z();
  if (std::abs(dz) > step_ && std::abs(dz) > tan_slope_ * L) {
    out.reject = Reject::kSlope;
    return out;
  }
  const Eigen::Vector2f lat =
      L > 1e-6f ? Eigen::Vector2f(-d.y() / L, d.x() / L) : Eigen::Vector2f(1, 0);
  const int n = std::max(1, int(std::ceil(L * inv_vs_)));
  bool reach = true;
  // z: support height of the previous sample; z2: of the one before. A leg's stride spans two
  // samples (0.2 m at 0.1 m voxels, less than a stair tread), so the height may change by at
  // most one step over two samples: a vertical face's noisy voxels cannot fake a staircase.
  float z = a.z(), z2 = a.z(), gap = 0, cost_sum = 0, len = 0;
  int supported = 0;
  Eigen::Vector3f prev = a;
  for (int k = 1; k < n; ++k) {
    const float t = float(k) / float(n);
    const float x = a.x() + d.x() * t, y = a.y() + d.y() * t;
    const std::optional<Support> s = support_dilated(x, y, z, step_);
    if (s) {
      if (s->state == TravState::kUntraversable) {
        out.reject = Reject::kUntraversable;
        return out;
      }
      if (!body_clear(x, y, s->p_m.z(), lat)) {
        out.reject = Reject::kCollision;
        return out;
      }
      if (std::abs(s->p_m.z() - z2) > step_) {
        out.reject = Reject::kStep;
        return out;
      }
      reach = reach && s->reachable;
      cost_sum += s->cost;
      ++supported;
      z2 = z;
      z = s->p_m.z();
      gap = 0;
    } else {
      // No support within a step of the previous sample: a wall, a drop, or unknown ground.
      if (!body_clear(x, y, z, lat)) {
        out.reject = Reject::kCollision;
        return out;
      }
      const int32_t cx = int32_t(std::floor(x * inv_vs_)), cy = int32_t(std::floor(y * inv_vs_));
      if (free(cell({cx, cy, zkey(z)})) && free(cell({cx, cy, zkey(z - step_)}))) {
        out.reject = Reject::kFallRisk;
        return out;
      }
      // Unknown ground: only tentative elements may bridge it, and only briefly.
      reach = false;
      z2 = z;
      gap += L / float(n);
      if (gap > float(opt_.max_gap_m)) {
        out.reject = Reject::kGap;
        return out;
      }
    }
    const Eigen::Vector3f cur(x, y, z);
    len += (cur - prev).norm();
    prev = cur;
  }
  if (std::abs(b.z() - z) > step_ || (n > 1 && std::abs(b.z() - z2) > step_)) {
    out.reject = Reject::kStep;
    return out;
  }
  len += (b - prev).norm();
  out.all_reachable = reach;
  out.length_m = len;
  out.mean_cost = supported ? cost_sum / float(supported) : 0.0f;
  return out;
}

}  // namespace storey::core::graph
