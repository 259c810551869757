#include "core/graph/topological_frontiers.hpp"

#include <algorithm>
#include <cmath>

namespace storey::core::graph {

using map::Occupancy;
using map::TravState;

TopologicalFrontiers::TopologicalFrontiers(const GraphOptions& opt) : opt_(opt) {
  // Omega_i: a sunflower (Vogel) pattern spreads |Omega_i| samples evenly over the unit disc,
  // deterministic and without clumps.
  const int n = std::max(1, opt_.surface_samples);
  const float golden = float(M_PI) * (3.0f - std::sqrt(5.0f));
  for (int k = 0; k < n; ++k) {
    const float r = std::sqrt((float(k) + 0.5f) / float(n));
    const float a = golden * float(k);
    disc_.emplace_back(r * std::cos(a), r * std::sin(a));
  }
}

int passage_probes(std::span<const ProbeState> ring) {
  const size_t n = ring.size();
  if (n < 3) return 0;
  int passages = 0;
  for (size_t k = 0; k < n; ++k)
    passages += ring[k] == ProbeState::kOpen && ring[(k + n - 1) % n] == ProbeState::kBlocked &&
                ring[(k + 1) % n] == ProbeState::kBlocked;
  return passages;
}

// Eq. 5. I(x, z_i) = 1 if a support surface lies within a step of z_i under x, or if x is an
// observed drop (known, so not under-observed). Samples hidden behind an obstacle at body
// height (walls) are not part of the node's region and are left out of Omega_i. With
// surface_seen_from_above a surface with no observed air over it (a slab's underside seen from
// the floor below) is missing, not support.
float TopologicalFrontiers::missing_surface_ratio(SupportQuery& q, const GraphNode& n,
                                                  int* samples) {
  const float radius = float(opt_.surface_radius_factor * opt_.r_e_m);
  const float hb = float(opt_.probe_height_m);
  const Eigen::Vector3f eye = n.p_m + Eigen::Vector3f(0, 0, hb);
  const float inv = 1.0f / q.voxel_size();
  int omega = 0, missing = 0;
  for (const Eigen::Vector2f& o : disc_) {
    const float x = n.p_m.x() + radius * o.x(), y = n.p_m.y() + radius * o.y();
    if (q.walk(eye, Eigen::Vector3f(x, y, eye.z()), false) == Occupancy::kOccupied) continue;
    ++omega;
    if (const auto s = q.surface_near(x, y, n.p_m.z(), q.step())) {
      if (!opt_.surface_seen_from_above) continue;
      const map::VoxelKey up{s->key.x, s->key.y, s->key.z + 1},
          up2{s->key.x, s->key.y, s->key.z + 2};
      // Rays grazing a floor from afar carve the voxels just above its underside free (test_ramp
      // seed 4: rho 0.21 at the mouth of a corridor seen only from below); with
      // map.floor_seen_from_above the underside itself says so.
      if (!s->underside &&
          (q.occupancy(up) == Occupancy::kFree || q.occupancy(up2) == Occupancy::kFree))
        continue;
    }
    const map::VoxelKey k{int32_t(std::floor(x * inv)), int32_t(std::floor(y * inv)),
                          int32_t(std::floor(n.p_m.z() * inv))};
    const map::VoxelKey below{k.x, k.y, int32_t(std::floor((n.p_m.z() - q.step()) * inv))};
    if (q.occupancy(k) == Occupancy::kFree && q.occupancy(below) == Occupancy::kFree) continue;
    ++missing;
  }
  *samples = omega;
  return omega ? float(missing) / float(omega) : 0.0f;
}

// C_exp: probes at body height along directions not covered by an edge (within alpha_min / 2);
// open if the probe crosses known free space and then reaches an unknown region (at least
// probe_unknown_m of it) without hitting an obstacle first. *up counts the open probes that
// climbed first.
int TopologicalFrontiers::open_directions(SupportQuery& q, const ReachableGraph& g, NodeId i,
                                          int* up, int* leads, int* passages,
                                          std::vector<ProbeExplanation>* explained) {
  const GraphNode& n = g.node(i);
  const int probes = std::max(1, opt_.probes);
  const float half = float(opt_.alpha_min_rad) * 0.5f;
  const float min_free = 2.0f * q.voxel_size();
  int open = 0;
  *up = 0;
  if (leads) *leads = 0;
  probe_state_.assign(size_t(probes), ProbeState::kOther);
  if (explained) explained->assign(size_t(probes), {});
  for (int k = 0; k < probes; ++k) {
    const float th = 2.0f * float(M_PI) * float(k) / float(probes);
    bool covered = false;
    for (int e = 0; e < n.degree && !covered; ++e) {
      const Eigen::Vector3f d = g.node(g.edge(n.edges[e]).other(i)).p_m - n.p_m;
      float diff = std::atan2(d.y(), d.x()) - th;
      diff = std::remainder(diff, 2.0f * float(M_PI));
      covered = std::abs(diff) < half;
    }
    if (explained) {
      (*explained)[size_t(k)].theta_rad = th;
      (*explained)[size_t(k)].covered = covered;
    }
    if (covered) continue;
    bool climbed = false, out_of_reach = false, blocked = false;
    SupportQuery::ProbeWhy why;
    const bool o = q.probe_open_climbing(
        n.p_m, Eigen::Vector2f(std::cos(th), std::sin(th)), float(opt_.probe_length_m),
        float(opt_.probe_height_m), min_free, float(opt_.probe_unknown_m), &climbed,
        leads ? &out_of_reach : nullptr, &blocked, explained ? &why : nullptr);
    probe_state_[size_t(k)] = o         ? ProbeState::kOpen
                              : blocked ? ProbeState::kBlocked
                                        : ProbeState::kOther;
    if (explained) {
      (*explained)[size_t(k)].state = probe_state_[size_t(k)];
      (*explained)[size_t(k)].why = why;
    }
    open += o;
    *up += o && climbed;
    if (leads) *leads += out_of_reach;
  }
  if (passages) *passages = passage_probes(probe_state_);
  return open;
}

// Ablation: the geometric boundary of C_reach near the node (reachable support columns with an
// 8-neighbour column that is unknown at that level or under-observed).
bool TopologicalFrontiers::near_reach_boundary(SupportQuery& q, const GraphNode& n) {
  const float vs = q.voxel_size();
  const int r = int(std::ceil(opt_.boundary_radius_m / vs));
  const int w = 2 * r + 3;
  // 0: unknown / under-observed, 1: reachable, 2: anything else.
  std::vector<uint8_t>& cls = cls_;
  cls.assign(size_t(w * w), 2);
  const float inv = 1.0f / vs;
  for (int dx = -r - 1; dx <= r + 1; ++dx)
    for (int dy = -r - 1; dy <= r + 1; ++dy) {
      const float x = n.p_m.x() + float(dx) * vs, y = n.p_m.y() + float(dy) * vs;
      const auto s = q.surface_near(x, y, n.p_m.z(), q.step());
      uint8_t c = 2;
      if (s) {
        c = s->reachable ? 1 : (s->state == TravState::kUnobserved ? 0 : 2);
      } else {
        const map::VoxelKey k{int32_t(std::floor(x * inv)), int32_t(std::floor(y * inv)),
                              int32_t(std::floor(n.p_m.z() * inv))};
        c = q.occupancy(k) == Occupancy::kUnknown ? 0 : 2;
      }
      cls[size_t((dx + r + 1) * w + dy + r + 1)] = c;
    }
  for (int dx = -r; dx <= r; ++dx)
    for (int dy = -r; dy <= r; ++dy) {
      if (dx * dx + dy * dy > r * r || cls[size_t((dx + r + 1) * w + dy + r + 1)] != 1) continue;
      for (int ex = -1; ex <= 1; ++ex)
        for (int ey = -1; ey <= 1; ++ey)
          if (cls[size_t((dx + ex + r + 1) * w + dy + ey + r + 1)] == 0) return true;
    }
  return false;
}

void TopologicalFrontiers::evaluate(ReachableGraph& g, SupportQuery& q, NodeId i) {
  GraphNode& n = g.mutable_node(i);
  if (!n.alive) return;
  const bool was = n.frontier();
  evaluate_flags(g, q, i);
  if (n.frontier() && !was) g.request_expand(i);  // the graph may extend from here
}

void TopologicalFrontiers::evaluate_flags(ReachableGraph& g, SupportQuery& q, NodeId i) {
  GraphNode& n = g.mutable_node(i);
  n.c_sur = n.c_exp = n.boundary = n.flight_lead = false;
  if (opt_.boundary_frontiers) {
    n.boundary = near_reach_boundary(q, n);
    return;
  }
  if (opt_.use_c_sur) {
    int omega = 0;
    n.rho = missing_surface_ratio(q, n, &omega);
    n.c_sur = omega * 4 >= std::max(1, opt_.surface_samples) && n.rho >= float(opt_.rho_min);
  }
  if (opt_.use_c_exp) {
    int up = 0, leads = 0, passages = 0;
    const int open = open_directions(q, g, i, &up, opt_.climb_frontiers ? &leads : nullptr,
                                     opt_.passage_frontiers ? &passages : nullptr);
    n.open_dirs = uint8_t(std::min(open, 255));
    n.flight_lead = leads > 0;
    // A flight of stairs is one probe wide: its walls close the probes beside it.
    // One probe that climbs it into unknown space is the way to the next floor (Sec. III-C).
    n.c_exp = open >= opt_.theta_min || (opt_.climb_frontiers && up >= 1) ||
              (opt_.passage_frontiers && passages >= 1);
  }
}

void TopologicalFrontiers::evaluate(ReachableGraph& g, const map::MapView& view, NodeId i) {
  SupportQuery q(view, opt_);
  evaluate(g, q, i);
}

std::vector<ProbeExplanation> TopologicalFrontiers::explain(const ReachableGraph& g,
                                                            const map::MapView& view, NodeId i) {
  std::vector<ProbeExplanation> out;
  if (i >= g.node_capacity() || !g.node(i).alive) return out;
  SupportQuery q(view, opt_);
  int up = 0, leads = 0, passages = 0;
  open_directions(q, g, i, &up, &leads, &passages, &out);
  return out;
}

FrontierUpdateStats TopologicalFrontiers::update(ReachableGraph& g, const map::MapView& view,
                                                 const Eigen::Vector3f& robot,
                                                 std::span<const Aabb> changed,
                                                 std::span<const Aabb> opened) {
  FrontierUpdateStats st;
  queued_.resize(g.node_capacity(), 0);
  std::vector<NodeId>& fresh = scratch_;
  fresh.clear();
  g.take_touched(fresh);
  if (!changed.empty() || !opened.empty()) {
    // C_exp probes reach probe_length_m, Omega_i reaches surface_radius_factor * r_e.
    const float reach =
        float(std::max(opt_.probe_length_m, opt_.surface_radius_factor * opt_.r_e_m));
    boxes_.clear();
    opened_.clear();
    for (const Aabb& b : changed)
      if (!b.empty()) boxes_.push_back(b.inflated(reach));
    for (const Aabb& b : opened)
      if (!b.empty()) opened_.push_back(b.inflated(reach));
    for (NodeId i = 0; i < g.node_capacity(); ++i) {
      const GraphNode& n = g.node(i);
      if (!n.alive) continue;
      bool in = false;
      for (const Aabb& b : opened_) in = in || b.contains(n.p_m);
      if (n.frontier())
        for (const Aabb& b : boxes_) in = in || b.contains(n.p_m);
      if (in) fresh.push_back(i);
    }
  }
  std::stable_sort(fresh.begin(), fresh.end(), [&](NodeId a, NodeId b) {
    return (g.node(a).p_m - robot).squaredNorm() < (g.node(b).p_m - robot).squaredNorm();
  });
  for (NodeId i : fresh)
    if (!queued_[i]) {
      queued_[i] = 1;
      queue_.push_back(i);
    }
  SupportQuery q(view, opt_);
  for (int b = 0; b < opt_.max_frontier_updates && !queue_.empty(); ++b) {
    const NodeId i = queue_.front();
    queue_.pop_front();
    queued_[i] = 0;
    if (!g.node(i).alive) continue;
    evaluate(g, q, i);
    ++st.evaluated;
  }
  for (NodeId i = 0; i < g.node_capacity(); ++i) {
    const GraphNode& n = g.node(i);
    if (!n.alive) continue;
    st.c_sur += n.c_sur;
    st.c_exp += n.c_exp;
    st.boundary += n.boundary;
    st.frontiers += n.frontier();
  }
  st.pending = uint32_t(queue_.size());
  return st;
}

}  // namespace storey::core::graph
