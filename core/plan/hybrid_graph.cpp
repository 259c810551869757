#include "core/plan/hybrid_graph.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/graph/support_query.hpp"

namespace storey::core::plan {

using graph::kNoId;
using graph::NodeId;
using graph::Reject;

const char* to_string(ZoneState s) {
  switch (s) {
    case ZoneState::kHypothetical:
      return "H";
    case ZoneState::kActive:
      return "A";
    case ZoneState::kCompleted:
      return "C";
  }
  return "?";
}

namespace {
constexpr float kRecycleTolM = 0.3f;  // a real id whose node moved this far is a new node
bool is_real_state(ElementState s) {
  return s != ElementState::kHypothetical;
}
}  // namespace

uint64_t HybridGraph::cell(double x, double y) const {
  const int64_t cx = int64_t(std::floor(x / grid_m_)), cy = int64_t(std::floor(y / grid_m_));
  return (uint64_t(cx + (1 << 30)) << 32) | uint64_t(cy + (1 << 30));
}

void HybridGraph::clear() {
  target_floor_ = -1;
  hyp_.clear();
  hyp_edges_.clear();
  hyp_adj_.clear();
  hyp_grid_.clear();
  zone_recs_.clear();
  real_zone_.clear();
  real_zone_p_.clear();
  nodes_.clear();
  edges_.clear();
  zones_.clear();
  csr_ = SearchGraph{};
  csr_real_.clear();
  last_version_ = ~uint64_t(0);
}

void HybridGraph::init_prior(const SearchGraph& ref, const ZonePartition& zones, double dz,
                             int32_t target_floor) {
  clear();
  target_floor_ = target_floor;
  const size_t n = ref.num_nodes();
  hyp_.resize(n);
  hyp_adj_.assign(n, {});
  for (uint32_t u = 0; u < n; ++u) {
    hyp_[u].p_m = ref.position(u) + Eigen::Vector3d(0, 0, dz);
    hyp_[u].zone = u < zones.zone_of.size() ? zones.zone_of[u] : -1;
  }
  for (uint32_t u = 0; u < n; ++u)
    ref.for_each_edge(u, [&](uint32_t v, double, uint32_t) {
      if (v <= u || v >= n) return;
      const uint32_t e = uint32_t(hyp_edges_.size());
      hyp_edges_.push_back({u, v});
      hyp_adj_[u].push_back(e);
      hyp_adj_[v].push_back(e);
    });
  hyp_grid_.reserve(n);
  for (uint32_t u = 0; u < n; ++u) hyp_grid_.push_back({cell(hyp_[u].p_m.x(), hyp_[u].p_m.y()), u});
  std::sort(hyp_grid_.begin(), hyp_grid_.end());
  zone_recs_.resize(zones.zones.size());
  for (const TaskZone& z : zones.zones) zone_recs_[size_t(z.id)].centre_hyp = int32_t(z.centre);
}

size_t HybridGraph::hypotheses_alive() const {
  size_t n = 0;
  for (const HypNode& h : hyp_) n += h.alive && h.bound == kNoId;
  return n;
}

bool HybridGraph::segment_blocked(const map::MapView& view, const Eigen::Vector3d& a,
                                  const Eigen::Vector3d& b) const {
  // The body's height band: just above a step, and near the top of the body.
  const RobotModel& r = view.robot();
  const double zs[2] = {r.step_height_m + view.voxel_size_m(), 0.9 * r.body_height_m};
  const double zmid = 0.5 * (a.z() + b.z());
  for (double h : zs) {
    const Eigen::Vector3f pa(float(a.x()), float(a.y()), float(zmid + h));
    const Eigen::Vector3f pb(float(b.x()), float(b.y()), float(zmid + h));
    if (view.is_occupied(view.key_of(pa)) || view.first_occupied(pa, pb)) return true;
  }
  return false;
}

void HybridGraph::bind_real_nodes(const graph::ReachableGraph& g, const FloorTracker& floors,
                                  const PlanOptions& opt, MaintenanceStats& st) {
  // Unbind hypotheses whose real node is gone (pruned, or its id recycled elsewhere).
  for (HypNode& h : hyp_) {
    if (h.bound == kNoId) continue;
    if (h.bound >= g.node_capacity() || !g.node(h.bound).alive ||
        (g.node(h.bound).p_m - h.bound_p).norm() > kRecycleTolM) {
      h.bound = kNoId;
      h.state = ElementState::kHypothetical;
      h.in_range = 0;  // standing alone again: checked on the next version wherever it is
      h.touched = check_cycle_ + 1;
    }
  }
  const double r2 = opt.hyp_promote_radius_m * opt.hyp_promote_radius_m;
  const int reach = int(std::ceil(opt.hyp_promote_radius_m / grid_m_));
  if (real_zone_.size() < g.node_capacity()) {
    real_zone_.resize(g.node_capacity(), -1);
    real_zone_p_.resize(g.node_capacity(), Eigen::Vector3f::Constant(1e30f));
  }
  for (NodeId id = 0; id < g.node_capacity(); ++id) {
    const graph::GraphNode& gn = g.node(id);
    if (!gn.alive || floors.floor_of(gn.p_m.z()) != target_floor_) continue;
    const double x = gn.p_m.x(), y = gn.p_m.y();
    for (int dx = -reach; dx <= reach; ++dx)
      for (int dy = -reach; dy <= reach; ++dy) {
        const uint64_t c = cell(x + dx * grid_m_, y + dy * grid_m_);
        auto it = std::lower_bound(hyp_grid_.begin(), hyp_grid_.end(), std::make_pair(c, 0u));
        for (; it != hyp_grid_.end() && it->first == c; ++it) {
          HypNode& h = hyp_[it->second];
          if (!h.alive || h.bound != kNoId) continue;
          const double ddx = h.p_m.x() - x, ddy = h.p_m.y() - y;
          if (ddx * ddx + ddy * ddy > r2 ||
              std::abs(h.p_m.z() - gn.p_m.z()) > opt.hyp_height_window_m)
            continue;
          h.bound = id;
          h.bound_p = gn.p_m;
          h.state = gn.state;
          h.touched = check_cycle_ + 1;  // its edges are re-checked on the next version
          ++st.bound;
          // The merged node keeps the hypothesis' zone unless it already has a label.
          if (real_zone_[id] < 0 || (real_zone_p_[id] - gn.p_m).norm() > kRecycleTolM) {
            real_zone_[id] = h.zone;
            real_zone_p_[id] = gn.p_m;
          }
        }
      }
  }
}

void HybridGraph::check_hypotheses(const map::MapView& view, const graph::ReachableGraph& g,
                                   const Eigen::Vector3d& robot, const PlanOptions& opt,
                                   const std::vector<graph::Aabb>* changed, MaintenanceStats& st) {
  // What a verdict reads: the column within the height window and the body's footprint around
  // it (SupportQuery's node test), or the voxels along an edge.
  constexpr float kReadMarginM = 1.0f;
  const uint32_t cycle = ++check_cycle_;
  auto changed_near = [&](const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    if (!changed) return true;
    const Eigen::Vector3f lo = a.cwiseMin(b).cast<float>().array() - kReadMarginM;
    const Eigen::Vector3f hi = a.cwiseMax(b).cast<float>().array() + kReadMarginM;
    for (const graph::Aabb& box : *changed)
      if (!box.empty() && (box.lo.array() <= hi.array()).all() &&
          (lo.array() <= box.hi.array()).all())
        return true;
    return false;
  };
  graph::SupportQuery q(view, g.options());
  const double r2 = opt.hyp_check_radius_m * opt.hyp_check_radius_m;
  auto near_robot = [&](const Eigen::Vector3d& p) {
    return (p - robot).head<2>().squaredNorm() <= r2 &&
           std::abs(p.z() - robot.z()) <= opt.floor_change_dz_m;
  };
  auto kill = [&](uint32_t h) {
    hyp_[h].alive = false;
    for (uint32_t e : hyp_adj_[h]) hyp_edges_[e].alive = false;
    ++st.discarded;
  };
  for (uint32_t i = 0; i < hyp_.size(); ++i) {
    HypNode& h = hyp_[i];
    if (!h.alive || h.bound != kNoId || h.state != ElementState::kHypothetical ||
        !near_robot(h.p_m))
      continue;
    const bool fresh = h.in_range + 1 != cycle;  // not in range on the previous check
    h.in_range = cycle;
    if (!fresh && !changed_near(h.p_m, h.p_m)) continue;
    h.touched = cycle;
    const Eigen::Vector3f p = h.p_m.cast<float>();
    bool negative = false;
    const auto s = q.surface_near(p.x(), p.y(), p.z(), opt.hyp_height_window_m);
    if (s && s->state == map::TravState::kTraversable) {
      bool confirmed = false;
      const Reject r = q.classify_node(*s, &confirmed);
      if (r == Reject::kNone) {
        h.state = confirmed ? ElementState::kConfirmed : ElementState::kTentative;
        h.p_m.z() = s->p_m.z();
        ++st.promoted;
        continue;
      }
      negative = r == Reject::kCollision || r == Reject::kFallRisk || r == Reject::kUntraversable;
    } else if (s) {
      negative = s->state == map::TravState::kUntraversable;
    } else {
      // No support in the window: evidence only if the column was seen there.
      negative = view.occupancy(p) != map::Occupancy::kUnknown &&
                 view.occupancy(Eigen::Vector3f(p + Eigen::Vector3f(0, 0, 0.3f))) !=
                     map::Occupancy::kUnknown;
    }
    if (!negative) continue;
    ++st.negative;
    if (++h.negative >= opt.hyp_discard_observations) kill(i);
  }
  // Edge validation.
  auto pos = [&](const HypNode& h) -> Eigen::Vector3d {
    return h.bound != kNoId ? g.node(h.bound).p_m.cast<double>() : h.p_m;
  };
  for (HypEdge& e : hyp_edges_) {
    if (!e.alive || e.state != ElementState::kHypothetical) continue;
    const HypNode &a = hyp_[e.a], &b = hyp_[e.b];
    if (!a.alive || !b.alive) {
      e.alive = false;
      continue;
    }
    const Eigen::Vector3d pa = pos(a), pb = pos(b);
    if (!near_robot(0.5 * (pa + pb))) continue;
    const bool fresh = e.in_range + 1 != cycle;
    e.in_range = cycle;
    if (!fresh && a.touched != cycle && b.touched != cycle && !changed_near(pa, pb)) continue;
    if (a.bound != kNoId && a.bound == b.bound) continue;  // both merged into one node
    if (segment_blocked(view, pa, pb)) {
      e.alive = false;
      ++st.edges_pruned;
      continue;
    }
    if (!is_real_state(a.state) || !is_real_state(b.state)) continue;
    const graph::EdgeCheck ec = q.check_edge(pa.cast<float>(), pb.cast<float>());
    if (ec.valid()) {
      e.state = ec.all_reachable ? ElementState::kConfirmed : ElementState::kTentative;
      ++st.edges_confirmed;
    } else if (ec.reject == Reject::kCollision || ec.reject == Reject::kStep ||
               ec.reject == Reject::kSlope || ec.reject == Reject::kFallRisk ||
               ec.reject == Reject::kUntraversable) {
      e.alive = false;
      ++st.edges_pruned;
    }
  }
}

void HybridGraph::compile(const map::MapView& view, const graph::ReachableGraph& g,
                          const FloorTracker& floors, const PlanOptions& opt) {
  nodes_.clear();
  edges_.clear();
  node_hyp_.clear();
  real_index_.assign(g.node_capacity(), kNoNode);
  for (NodeId id = 0; id < g.node_capacity(); ++id) {
    const graph::GraphNode& gn = g.node(id);
    if (!gn.alive) continue;
    HybridNode n;
    n.p_m = gn.p_m.cast<double>();
    n.state = gn.state;
    n.real = id;
    n.on_target = has_prior() && floors.floor_of(gn.p_m.z()) == target_floor_;
    n.frontier = gn.frontier();
    if (n.on_target && id < real_zone_.size() && real_zone_[id] >= 0 &&
        (real_zone_p_[id] - gn.p_m).norm() <= kRecycleTolM)
      n.zone = real_zone_[id];
    real_index_[id] = uint32_t(nodes_.size());
    nodes_.push_back(n);
    node_hyp_.push_back(-1);
  }
  hyp_index_.assign(hyp_.size(), kNoNode);
  for (uint32_t i = 0; i < hyp_.size(); ++i) {
    const HypNode& h = hyp_[i];
    if (!h.alive) continue;
    if (h.bound != kNoId) {
      hyp_index_[i] = real_index_[h.bound];
      continue;
    }
    HybridNode n;
    n.p_m = h.p_m;
    n.state = h.state;
    n.zone = h.zone;
    n.on_target = true;
    hyp_index_[i] = uint32_t(nodes_.size());
    nodes_.push_back(n);
    node_hyp_.push_back(int32_t(i));
  }
  for (graph::EdgeId e = 0; e < g.edge_capacity(); ++e) {
    const graph::GraphEdge& ge = g.edge(e);
    if (!ge.alive) continue;
    const uint32_t a = real_index_[ge.a], b = real_index_[ge.b];
    if (a != kNoNode && b != kNoNode) edges_.push_back({a, b, ge.state});
  }
  for (const HypEdge& he : hyp_edges_) {
    if (!he.alive) continue;
    const uint32_t a = hyp_index_[he.a], b = hyp_index_[he.b];
    if (a == kNoNode || b == kNoNode || a == b) continue;
    edges_.push_back({a, b, he.state});
  }
  // Bridges: hypothetical links from the nearest real target-floor nodes to each standing-alone
  // hypothesis, so the hybrid graph continues where G_real ends.
  for (uint32_t u = 0; u < nodes_.size(); ++u) {
    if (node_hyp_[u] < 0) continue;
    const Eigen::Vector3f p = nodes_[u].p_m.cast<float>();
    near_.clear();  // nodes_within appends
    g.nodes_within(p, float(opt.hyp_bridge_radius_m), float(opt.hyp_height_window_m), near_);
    std::sort(near_.begin(), near_.end(), [&](NodeId a, NodeId b) {
      const float da = (g.node(a).p_m - p).squaredNorm(), db = (g.node(b).p_m - p).squaredNorm();
      return da < db || (da == db && a < b);
    });
    // At most the 3 nearest candidates are checked (bounded work: the obstacle walks are the
    // cost of this loop), at most 2 bridges kept.
    int added = 0, tried = 0;
    for (NodeId r : near_) {
      const uint32_t v = real_index_[r];
      if (v == kNoNode || !nodes_[v].on_target) continue;
      if (++tried > 3) break;
      if (segment_blocked(view, nodes_[u].p_m, nodes_[v].p_m)) continue;
      edges_.push_back({v, u, ElementState::kHypothetical});
      if (++added == 2) break;
    }
  }
  // CSR (each undirected edge in both directions) with a "real" flag per slot.
  const size_t n = nodes_.size();
  csr_.positions_m.resize(n);
  for (size_t u = 0; u < n; ++u) csr_.positions_m[u] = nodes_[u].p_m;
  deg_.assign(n + 1, 0);
  for (const HybridEdge& e : edges_) {
    ++deg_[e.a + 1];
    ++deg_[e.b + 1];
  }
  csr_.offsets.assign(n + 1, 0);
  for (size_t u = 0; u < n; ++u) csr_.offsets[u + 1] = csr_.offsets[u] + deg_[u + 1];
  const size_t m = csr_.offsets[n];
  csr_.targets.resize(m);
  csr_.weights.resize(m);
  csr_real_.resize(m);
  std::copy(csr_.offsets.begin(), csr_.offsets.end() - 1, deg_.begin());
  for (const HybridEdge& e : edges_) {
    const double w = (nodes_[e.a].p_m - nodes_[e.b].p_m).norm();
    const uint8_t real = is_real_state(e.state) && node_real(e.a) && node_real(e.b);
    for (int d = 0; d < 2; ++d) {
      const uint32_t from = d ? e.b : e.a, to = d ? e.a : e.b;
      const uint32_t slot = deg_[from]++;
      csr_.targets[slot] = to;
      csr_.weights[slot] = w;
      csr_real_[slot] = real;
    }
  }
}

void HybridGraph::set_label(uint32_t u, int32_t zone) {
  HybridNode& n = nodes_[u];
  n.zone = zone;
  if (n.real != kNoId) {
    real_zone_[n.real] = zone;
    real_zone_p_[n.real] = n.p_m.cast<float>();
  } else if (node_hyp_[u] >= 0) {
    hyp_[size_t(node_hyp_[u])].zone = zone;
  }
}

uint32_t HybridGraph::centre_index(const ZoneRec& z) const {
  if (z.centre_hyp >= 0 && size_t(z.centre_hyp) < hyp_index_.size())
    return hyp_index_[size_t(z.centre_hyp)];
  if (z.centre_real != kNoId && z.centre_real < real_index_.size())
    return real_index_[z.centre_real];
  return kNoNode;
}

void HybridGraph::maintain_zones(const PlanOptions& opt, MaintenanceStats& st) {
  const uint32_t n = uint32_t(nodes_.size());
  mark_.assign(n, -1);
  // Members per zone (counting sort by label).
  const size_t nz = zone_recs_.size();
  std::vector<uint32_t> start(nz + 1, 0), members;
  for (const HybridNode& hn : nodes_)
    if (hn.on_target && hn.zone >= 0) ++start[size_t(hn.zone) + 1];
  for (size_t z = 0; z < nz; ++z) start[z + 1] += start[z];
  members.resize(start[nz]);
  {
    std::vector<uint32_t> fill(start.begin(), start.end() - 1);
    for (uint32_t u = 0; u < n; ++u)
      if (nodes_[u].on_target && nodes_[u].zone >= 0) members[fill[size_t(nodes_[u].zone)]++] = u;
  }
  // Component labelling by BFS along edges, restricted to nodes satisfying `in`.
  auto bfs = [&](uint32_t s, int32_t label, auto&& in) {
    comp_.clear();
    stack_.assign(1, s);
    mark_[s] = label;
    while (!stack_.empty()) {
      const uint32_t u = stack_.back();
      stack_.pop_back();
      comp_.push_back(u);
      csr_.for_each_edge(u, [&](uint32_t v, double, uint32_t) {
        if (mark_[v] != label && in(v)) {
          mark_[v] = label;
          stack_.push_back(v);
        }
      });
    }
  };
  // 1) Connectivity split.
  for (size_t z = 0; z < nz; ++z) {
    const uint32_t b = start[z], e = start[z + 1];
    if (b == e) continue;
    const int32_t zid = int32_t(z);
    auto in_zone = [&](uint32_t v) { return nodes_[v].on_target && nodes_[v].zone == zid; };
    uint32_t c = centre_index(zone_recs_[z]);
    if (c != kNoNode && !in_zone(c)) c = kNoNode;
    int32_t label = -2;  // component labels of this zone: -3, -4, ... (reset below)
    uint32_t keep_seed = kNoNode;
    size_t keep_size = 0, c_size = 0;
    for (uint32_t i = b; i < e; ++i) {
      const uint32_t u = members[i];
      if (mark_[u] <= -3) continue;  // in a component found already
      bfs(u, --label, in_zone);
      if (comp_.size() > keep_size) {
        keep_size = comp_.size();
        keep_seed = u;
      }
      if (c != kNoNode && mark_[c] == label) c_size = comp_.size();
    }
    if (c != kNoNode && !(c_size == 1 && e - b > 1)) keep_seed = c;
    const int32_t keep = mark_[keep_seed];
    for (uint32_t i = b; i < e; ++i) {
      const uint32_t u = members[i];
      if (mark_[u] != keep) {
        set_label(u, -1);
        ++st.split_detached;
      }
    }
    for (uint32_t i = b; i < e; ++i) mark_[members[i]] = -1;
  }
  // Zone sizes and centroid sums after the split.
  std::vector<int> size(nz, 0);
  std::vector<Eigen::Vector3d> sum(nz, Eigen::Vector3d::Zero());
  for (const HybridNode& hn : nodes_)
    if (hn.on_target && hn.zone >= 0) {
      ++size[size_t(hn.zone)];
      sum[size_t(hn.zone)] += hn.p_m;
    }
  // 2) Unassigned components, 3) reassignment / merge.
  auto unassigned = [&](uint32_t v) { return nodes_[v].on_target && nodes_[v].zone < 0; };
  std::vector<uint32_t> comp;
  for (uint32_t u = 0; u < n; ++u) {
    if (!unassigned(u) || mark_[u] == -2) continue;
    bfs(u, -2, unassigned);
    comp = comp_;
    ++st.components;
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (uint32_t v : comp) c += nodes_[v].p_m;
    c /= double(comp.size());
    cross_.assign(zone_recs_.size(), 0);
    for (uint32_t v : comp)
      csr_.for_each_edge(v, [&](uint32_t w, double, uint32_t) {
        if (nodes_[w].on_target && nodes_[w].zone >= 0) ++cross_[size_t(nodes_[w].zone)];
      });
    int32_t best = -1;
    double best_d = 0;
    for (size_t z = 0; z < zone_recs_.size(); ++z) {
      if (cross_[z] == 0 || size[z] + int(comp.size()) > opt.zone_capacity) continue;
      const double d = (sum[z] / double(size[z]) - c).norm();
      const bool ok = cross_[z] >= opt.zone_merge_cross_edges || d <= opt.zone_merge_distance_m ||
                      int(comp.size()) < opt.min_zone_nodes;
      if (!ok) continue;
      if (best < 0 || cross_[z] > cross_[size_t(best)] ||
          (cross_[z] == cross_[size_t(best)] && d < best_d)) {
        best = int32_t(z);
        best_d = d;
      }
    }
    if (best >= 0) {
      ++st.merged;
    } else {
      best = int32_t(zone_recs_.size());
      zone_recs_.push_back({});
      size.push_back(0);
      sum.push_back(Eigen::Vector3d::Zero());
      ++st.new_zones;
    }
    for (uint32_t v : comp) {
      set_label(v, best);
      ++size[size_t(best)];
      sum[size_t(best)] += nodes_[v].p_m;
    }
  }
}

void HybridGraph::collect_zones(const Eigen::Vector3d& robot, const PlanOptions& opt) {
  zones_.clear();
  std::vector<int32_t> slot(zone_recs_.size(), -1);
  for (uint32_t u = 0; u < nodes_.size(); ++u) {
    const HybridNode& hn = nodes_[u];
    if (!hn.on_target || hn.zone < 0) continue;
    int32_t& s = slot[size_t(hn.zone)];
    if (s < 0) {
      s = int32_t(zones_.size());
      zones_.emplace_back();
      zones_.back().id = hn.zone;
    }
    HybridZone& z = zones_[size_t(s)];
    z.nodes.push_back(u);
    if (node_real(u)) {
      ++z.real_nodes;
    } else {
      ++z.hyp_nodes;
    }
    z.frontier_nodes += hn.frontier;
  }
  for (size_t z = 0; z < zone_recs_.size(); ++z) zone_recs_[z].alive = slot[z] >= 0;
  std::sort(zones_.begin(), zones_.end(),
            [](const HybridZone& a, const HybridZone& b) { return a.id < b.id; });
  for (HybridZone& z : zones_) {
    ZoneRec& rec = zone_recs_[size_t(z.id)];
    TaskZone tz;
    tz.nodes = z.nodes;
    compute_zone_centre(csr_.positions_m, tz);
    z.centroid_m = tz.centroid_m;
    const uint32_t kept = centre_index(rec);
    // Without maintenance the prior's centre stays while it is a member.
    z.centre = (!opt.incremental_maintenance && kept != kNoNode && nodes_[kept].zone == z.id)
                   ? kept
                   : tz.centre;
    const HybridNode& c = nodes_[z.centre];
    rec.centre_real = c.real;
    rec.centre_hyp = c.real == kNoId ? node_hyp_[z.centre] : -1;
    rec.visited = rec.visited || ((c.p_m - robot).head<2>().norm() <= opt.zone_visit_radius_m &&
                                  std::abs(c.p_m.z() - robot.z()) < opt.floor_change_dz_m);
    z.visited = rec.visited;
    if (z.real_nodes == 0)
      z.state = ZoneState::kHypothetical;
    else if (z.frontier_nodes == 0 && (z.hyp_nodes == 0 || z.visited))
      z.state = ZoneState::kCompleted;
    else
      z.state = ZoneState::kActive;
  }
}

MaintenanceStats HybridGraph::update(const map::MapView& view, uint64_t map_version,
                                     const graph::ReachableGraph& g, const FloorTracker& floors,
                                     const Eigen::Vector3d& robot, const PlanOptions& opt,
                                     const std::vector<graph::Aabb>* changed) {
  MaintenanceStats st;
  if (!has_prior()) {
    nodes_.clear();
    edges_.clear();
    zones_.clear();
    csr_ = SearchGraph{};
    csr_real_.clear();
    return st;
  }
  probe_mark(probe_, PlanStage::kHybridBind);
  bind_real_nodes(g, floors, opt, st);
  if (map_version != last_version_) {
    last_version_ = map_version;
    probe_mark(probe_, PlanStage::kHybridCheck);
    check_hypotheses(view, g, robot, opt, changed, st);
  }
  probe_mark(probe_, PlanStage::kHybridCompile);
  compile(view, g, floors, opt);
  probe_mark(probe_, PlanStage::kHybridZones);
  if (opt.incremental_maintenance) maintain_zones(opt, st);
  collect_zones(robot, opt);
  st.hyp_alive = uint32_t(hypotheses_alive());
  return st;
}

}  // namespace storey::core::plan
