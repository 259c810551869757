// TraversabilityMap: terrain statistics and traversability state, paper Sec. III-A Eq. 1-3.
#include <cmath>

#include <Eigen/Eigenvalues>

#include "core/map/point_plane.hpp"
#include "core/map/traversability_map.hpp"

namespace storey::core::map {

TravUpdateStats TraversabilityMap::update_traversability() {
  TravUpdateStats st;
  // 1. Dirty set: every occupied voxel whose tau(v) can depend on a changed voxel c, i.e. v
  //    with c in its aggregation window (|dxy| <= r_agg, |dz| <= dz_agg), in its clearance
  //    column or fall-support columns (c.z - v.z in [-dz_step, h_clear]).
  const int r = std::max(r_agg_, r_col_);
  const int up = std::max(dz_step_, dz_agg_) + 1, down = h_clear_ + 1;
  for (const VoxelKey& c : changed_) {
    if (Cell* cc = wcell(c)) cc->flags &= ~Cell::kChanged;
    for (int dx = -r; dx <= r; ++dx)
      for (int dy = -r; dy <= r; ++dy)
        for (int32_t z = c.z - down; z <= c.z + up; ++z) {
          const VoxelKey v{c.x + dx, c.y + dy, z};
          const Cell* rc = rcell(v);
          if (!rc || (rc->flags & Cell::kQueued)) continue;
          if (!occupied(rc) && rc->state == TravState::kNone) continue;
          wcell(v)->flags |= Cell::kQueued;
          dirty_.push_back(v);
        }
  }
  changed_.clear();

  // 2. Step edges first: evaluate() reads the neighbours' surface heights, which depend on it.
  for (const VoxelKey& k : dirty_) {
    const Cell* c = rcell(k);
    if (!c || c->stats == Cell::kNoStats) continue;
    const bool edge = occupied(c) && step_edge(k, *reader_.stats(k));
    if (edge == bool(reader_.stats(k)->shape & VoxelStats::kStepEdge)) continue;
    VoxelBlock* b = wblock(k, false);
    VoxelStats& st = b->stats[b->cells[cell_index(k)].stats];
    st.shape = edge ? (st.shape | VoxelStats::kStepEdge) : (st.shape & ~VoxelStats::kStepEdge);
  }

  // 3. Re-evaluate. evaluate() reads only statistics, step-edge shapes and occupancy of
  //    neighbours, never their states, so the order of the dirty set does not matter.
  for (const VoxelKey& k : dirty_) {
    VoxelBlock* b = wblock(k, false);
    Cell& c = b->cells[cell_index(k)];
    c.flags &= ~Cell::kQueued;
    VoxelStats* s = c.stats == Cell::kNoStats ? nullptr : &b->stats[c.stats];
    const TravState old = c.state;
    const bool was_reach = c.flags & Cell::kReachable;
    const uint32_t old_dist = s ? s->reach_dist : 0;
    const TravState now = evaluate(k, s);
    // evaluate() only reads through the read cache; re-fetch in case nothing changed.
    b = wblock(k, false);
    Cell& c2 = b->cells[cell_index(k)];
    c2.state = now;
    ++st.evaluated;
    if (now != old) {
      ++st.state_changes;
      if (old == TravState::kTraversable) --trav_count_;
      if (now == TravState::kTraversable) ++trav_count_;
    }
    if (now != old || now == TravState::kTraversable || was_reach)
      reach_changed_.push_back({k, old_dist, was_reach});
    if (now == TravState::kNone) {  // turned free: statistics are stale
      // Members of C_reach always own statistics (reach_dist lives there); the reachable pass
      // still sees this voxel through reach_changed_ (was_reach, old_dist).
      if (c2.flags & Cell::kReachable) {
        c2.flags &= ~Cell::kReachable;
        --reach_count_;
      }
      b->release_stats(c2);
    }
  }
  dirty_.clear();
  return st;
}

bool TraversabilityMap::step_edge(const VoxelKey& k, const VoxelStats& s) {
  if (s.count < uint32_t(opt_.n_min)) return false;
  auto stats_of = [this](const VoxelKey& w) { return occupied(rcell(w)) ? rstats(w) : nullptr; };
  const Cell* up = rcell({k.x, k.y, k.z + 1});
  if (!up || !(up->flags & Cell::kObserved) || occupied(up)) return false;  // rays crossed above
  const double vs = opt_.voxel_size_m;
  const double top = sheet_top_offset(s);  // upper end of the points
  if (top < 0.0) return false;             // they end in v's lower half
  const PointPlane own =
      opt_.pool_short_risers ? riser_plane(s, stats_of({k.x, k.y, k.z - 1}), vs) : point_plane(s);
  if (!steep_sheet(own)) return false;
  // A step, not a slope: along the sheet's normal one neighbouring column holds no surface
  // within a step of v's top that is a little higher (a slope rises on), and one holds none
  // level with it (the step down in front; a tread seen edge-on there reads as none). Heights
  // from the points' means, so this test reads no other voxel's step-edge flag.
  const double h = (k.z + 0.5) * vs + std::min(top, 0.5 * vs);
  const Eigen::Vector2d nh = own.normal.head<2>().normalized();
  int drop_sides = 0, drop_sign = 0;
  for (int side = -1; side <= 1; side += 2) {
    const int32_t cx = k.x + int32_t(std::lround(side * nh.x()));
    const int32_t cy = k.y + int32_t(std::lround(side * nh.y()));
    bool level = false;
    for (int32_t z = k.z - dz_step_ - 1; z <= k.z + dz_step_ + 1; ++z) {
      const Cell* cw = rcell({cx, cy, z});
      if (!occupied(cw) || occupied(rcell({cx, cy, z + 1}))) continue;
      const VoxelStats* sw = cw->stats == Cell::kNoStats ? nullptr : reader_.stats({cx, cy, z});
      const double hw = (z + 0.5) * vs + (sw && sw->count ? sw->mean[2] : 0.0);
      if (hw > h + 0.5 * vs && hw <= h + robot_.step_height_m) return false;  // slope up
      // Level ground beside v: a tread, not another sheet of the same riser (a riser near a
      // column boundary smears into both columns).
      if (hw > h - 0.08 && hw <= h + 0.5 * vs)
        level |= !sw || sw->count < uint32_t(opt_.n_min) || !steep_sheet(point_plane(*sw));
    }
    if (level) continue;
    // A ledge, not a step: rays crossed the drop column more than a step below v's top (under
    // a nosing that space is the stair's solid, never seen; under a slab edge over a stairwell
    // it is open air).
    if (opt_.pool_short_risers) {
      const Cell* below =
          rcell({cx, cy, int32_t(std::floor((h - robot_.step_height_m - 0.03) / vs))});
      if (below && (below->flags & Cell::kObserved) && !occupied(below)) return false;
    }
    ++drop_sides, drop_sign = side;
  }
  if (drop_sides == 0) return false;
  // A riser on a column boundary smears into the columns on both sides. The column in front of
  // it (its sheet lies on the far side, toward the step up) is mostly the lower ground, not a
  // nosing.
  if (drop_sides == 1) {
    const double d = drop_sign * (s.mean[0] * nh.x() + s.mean[1] * nh.y());  // toward the drop
    if (d < -0.2 * vs) return false;
  }
  return true;
}

// A floor on a voxel boundary (z = 0 in the simulator; anywhere in a building) spills a few
// noisy points into the voxel above its own. Under N_min that spill read S_unobs, sat on top of
// the well-observed voxel (no top surface then), grazing rays carved it (a voxel of < 3 points
// takes every miss) and the next scan's noise put it back: frontiers that came and went in
// explored corridors (test_ramp's). A spill low in its voxel over a level, well-observed sheet
// that reaches the top of its own voxel is that surface: judged with its neighbourhood (Eq. 1
// pools the columns around it) like any top voxel.
bool TraversabilityMap::surface_spill(const VoxelKey& k, const VoxelStats& s) {
  const float vs = float(opt_.voxel_size_m);
  if (!opt_.spill_is_surface || s.count == 0 || s.mean[2] > -0.25f * vs) return false;
  const VoxelKey kb{k.x, k.y, k.z - 1};
  const Cell* b = rcell(kb);
  if (!occupied(b) || b->stats == Cell::kNoStats) return false;
  const VoxelStats* sb = reader_.stats(kb);
  if (sb->count < uint32_t(opt_.n_min) || (sb->shape & VoxelStats::kStepEdge) ||
      sb->mean[2] < 0.25f * vs)
    return false;
  const PointPlane p = point_plane(*sb);
  return clear_plane(p) && std::abs(p.normal.z()) >= std::cos(robot_.max_slope_rad);
}

TravState TraversabilityMap::evaluate(const VoxelKey& k, VoxelStats* s) {
  const Cell* c = rcell(k);
  if (!occupied(c)) return TravState::kNone;
  if (!s || (s->count < uint32_t(opt_.n_min) && !surface_spill(k, *s))) {  // Eq. 3, first case
    if (s) s->count_eval = s->count;
    return TravState::kUnobserved;
  }
  s->count_eval = s->count;
  s->reasons = 0;
  if (occupied(rcell({k.x, k.y, k.z + 1}))) {  // not a top surface: cannot stand on it
    s->reasons = VoxelStats::kReasonNotTop;
    return TravState::kUntraversable;
  }
  const double vs = opt_.voxel_size_m;
  const float h_v = surface_height(k, s);

  // Eq. 1: aggregate the statistics of the support voxels in the neighbourhood (radius
  // r_agg, surface height within neighbourhood_dz_m of v) in v's centre frame, in double:
  // sums of n, n*m and M2 + n*m*m^T, then the pooled covariance.
  double n_agg = 0;
  Eigen::Vector3d sum_m = Eigen::Vector3d::Zero();
  Eigen::Matrix3d sum_s = Eigen::Matrix3d::Zero();
  const int r2 = r_agg_ * r_agg_;
  for (int dx = -r_agg_; dx <= r_agg_; ++dx)
    for (int dy = -r_agg_; dy <= r_agg_; ++dy) {
      if (dx * dx + dy * dy > r2) continue;
      bool above_occ = occupied(rcell({k.x + dx, k.y + dy, k.z + dz_agg_ + 1}));
      for (int dz = dz_agg_; dz >= -dz_agg_; --dz) {  // top-down: "above" is known
        const VoxelKey w{k.x + dx, k.y + dy, k.z + dz};
        const Cell* cw = rcell(w);
        const bool occ = occupied(cw);
        if (occ && !above_occ && cw->stats != Cell::kNoStats) {
          const VoxelStats* sw = reader_.stats(w);
          // A step edge's points are its riser, not the surface it stands for.
          if (sw->count && !(sw->shape & VoxelStats::kStepEdge) &&
              std::abs(surface_height(w, sw) - h_v) <= opt_.neighbourhood_dz_m) {
            const double n = sw->count;
            const Eigen::Vector3d m(sw->mean[0] + dx * vs, sw->mean[1] + dy * vs,
                                    sw->mean[2] + dz * vs);
            sum_m += n * m;
            Eigen::Matrix3d m2;
            m2 << sw->m2[0], sw->m2[1], sw->m2[2], sw->m2[1], sw->m2[3], sw->m2[4], sw->m2[2],
                sw->m2[4], sw->m2[5];
            sum_s += m2 + n * m * m.transpose();
            n_agg += n;
          }
        }
        above_occ = occ;
      }
    }
  const bool edge = s->shape & VoxelStats::kStepEdge;
  double cost = 0, nz = 1;
  if (edge) {
    // A stair nosing or kerb: the riser's top is observed, the tread behind it inferred (treads
    // above the sensor are seen edge-on, and a tread on a voxel boundary is grazed free).
    // Its cost is the under-observation term alone, u(v) = 1; slope and roughness of the
    // pooled points would be those of the risers around it.
    cost = opt_.w_u;
  } else {
    const Eigen::Vector3d mean = sum_m / n_agg;
    const Eigen::Matrix3d cov = sum_s / n_agg - mean * mean.transpose();
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es;
    es.computeDirect(cov);
    const Eigen::Vector3d ev = es.eigenvalues().cwiseMax(0.0);  // ascending l1 <= l2 <= l3
    // Collinear points (a single scan line on the floor) leave the normal undetermined: not yet
    // observable, like N(v) < N_min.
    if (!(ev[2] > 0) || ev[1] < 1e-3 * ev[2]) {
      s->reasons = VoxelStats::kReasonDegenerate;
      return TravState::kUnobserved;
    }
    const Eigen::Vector3d nrm = es.eigenvectors().col(0);
    const double slope = std::acos(std::min(1.0, std::abs(nrm.z())));  // s(v), Eq. 1
    // MapOptions::floor_seen_from_above: every ray that hit v rose more steeply than the surface
    // (+0.02 for noise): its underside (a ceiling), whatever lies unseen above it.
    if (opt_.floor_seen_from_above && s->min_rise >= 100.0 * std::tan(slope) + 2.0) {
      s->reasons = VoxelStats::kReasonNotTop;
      return TravState::kUntraversable;
    }
    const double rough = 1.0 - (ev[1] - ev[0]) / std::max(1e-18, ev[1] + ev[0]);  // r(v), Eq. 1
    const double under = 1.0 - std::min(1.0, n_agg / double(opt_.n_ref));         // u(v)
    // Eq. 2 with s_bar = s / max_slope, r_bar = r, u_bar = u (all 1 at their limits).
    cost = opt_.w_s * slope / robot_.max_slope_rad + opt_.w_r * rough + opt_.w_u * under;
    // Step edges: where the neighbourhood straddles a stair nosing, the pooled points include the
    // riser below and the plane fit tilts toward vertical, although v's own points are a flat
    // tread. If v alone holds a well-spread, level plane, its own slope and roughness stand for
    // it (the riser voxels keep their vertical fit and stay S_untrav).
    if (cost > opt_.tau_c && s->count >= uint32_t(opt_.n_min)) {
      const PointPlane own = point_plane(*s);
      const Eigen::Vector3d& oev = own.eigenvalues;
      if (oev[2] > 0 && oev[1] >= 1e-2 * oev[2]) {  // not collinear
        const double oslope = std::acos(std::min(1.0, std::abs(own.normal.z())));
        const double orough = 1.0 - (oev[1] - oev[0]) / std::max(1e-18, oev[1] + oev[0]);
        if (oslope <= 0.5 * robot_.max_slope_rad)
          cost = std::min(cost, opt_.w_s * oslope / robot_.max_slope_rad + opt_.w_r * orough +
                                    opt_.w_u * under);
      }
    }
    nz = std::abs(nrm.z());
  }
  s->cost = float(cost);
  s->normal_z = float(nz);
  if (cost > opt_.tau_c) s->reasons |= VoxelStats::kReasonCost;

  // R_col(v): an occupied voxel whose points lie above the step height and below the body
  // clearance, within collision_radius_m of v's column.
  // The height v's body would stand at (standing_height): against the mean, the next tread
  // (one 0.167 m rise up) would read higher than the 0.18 m step and block every nosing.
  const double h_top = standing_height(k, s);
  const double clear = robot_.body_height_m + robot_.body_margin_m;
  const int rc2 = r_col_ * r_col_;
  for (int dx = -r_col_; dx <= r_col_ && !(s->reasons & VoxelStats::kReasonCollision); ++dx)
    for (int dy = -r_col_; dy <= r_col_; ++dy) {
      if (dx * dx + dy * dy > rc2) continue;
      bool hit = false;
      for (int dz = 0; dz <= h_clear_ + 1 && !hit; ++dz) {
        const VoxelKey w{k.x + dx, k.y + dy, k.z + dz};
        const Cell* cw = rcell(w);
        if (!occupied(cw)) continue;
        const VoxelStats* sw = cw->stats == Cell::kNoStats ? nullptr : reader_.stats(w);
        const double dh = surface_height(w, sw) - h_top;
        hit = dh > robot_.step_height_m + step_slack(s, sw) && dh <= clear;
      }
      if (hit) {
        s->reasons |= VoxelStats::kReasonCollision;
        break;
      }
    }

  // R_fall(v): a neighbour column is a drop if nothing occupied lies from one step below v's
  // surface up to the body clearance (no ground to stand on, and no wall) while the space just
  // below v's level is observed free (v's own level is not evidence: rays graze through the
  // upper part of floor voxels) and, further down, free to the lower ground (not unknown). Unknown
  // columns are no evidence either way (under-observed ground is S_unobs territory, not a ledge).
  // Too many drops in the neighbourhood: a ledge. Heights compared where the feet stand
  // (standing_height, h_top): at a nosing, mean heights pulled down by riser points read a 0.167 m
  // rise as a drop beyond the 0.18 m step.
  int total = 0, drops = 0;
  for (int dx = -r_agg_; dx <= r_agg_; ++dx)
    for (int dy = -r_agg_; dy <= r_agg_; ++dy) {
      if ((dx == 0 && dy == 0) || dx * dx + dy * dy > r2) continue;
      ++total;
      bool safe = false, seen_free = false;
      for (int dz = -dz_step_ - 1; dz <= h_clear_ + 1 && !safe; ++dz) {
        const VoxelKey w{k.x + dx, k.y + dy, k.z + dz};
        const Cell* cw = rcell(w);
        if (!cw || !(cw->flags & Cell::kObserved)) continue;
        if (!occupied(cw)) {
          seen_free |= dz >= -dz_step_ && dz < 0;
          continue;
        }
        const double dh =
            standing_height(w, cw->stats == Cell::kNoStats ? nullptr : reader_.stats(w)) - h_top;
        safe = dh >= -robot_.step_height_m && dh <= clear;
      }
      if (safe || !seen_free) continue;
      // Free just below v's level, but nothing observed under that: a tread seen edge-on (rays
      // grazing over it keep its voxel free; the stair's solid under it is never seen), not a
      // ledge. Under a ledge rays reach the open space or the lower ground.
      bool drop = false;
      for (int dz = -dz_step_ - 1; dz >= -3 * dz_step_ && !drop; --dz) {
        const Cell* cw = rcell({k.x + dx, k.y + dy, k.z + dz});
        drop = cw && (cw->flags & Cell::kObserved);
      }
      drops += drop;
    }
  if (total > 0 && double(drops) > (1.0 - opt_.fall_support_ratio) * double(total))
    s->reasons |= VoxelStats::kReasonFall;

  return s->reasons ? TravState::kUntraversable : TravState::kTraversable;  // Eq. 3
}

}  // namespace storey::core::map
