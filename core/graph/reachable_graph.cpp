#include "core/graph/reachable_graph.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace storey::core::graph {

namespace {
// Own uniform mapping (std::uniform_real_distribution is not specified bit for bit).
double u01(std::mt19937_64& rng) {
  return double(rng() >> 11) * 0x1.0p-53;
}

float wrap_pi(float a) {
  while (a > float(M_PI)) a -= 2.0f * float(M_PI);
  while (a < -float(M_PI)) a += 2.0f * float(M_PI);
  return a;
}
}  // namespace

Aabb scan_bounds(const Eigen::Vector3f& origin, std::span<const Eigen::Vector3f> points) {
  Aabb b;
  if (origin.allFinite()) b.extend(origin);
  for (const Eigen::Vector3f& p : points)
    if (p.allFinite()) b.extend(p);
  return b;
}

ReachableGraph::ReachableGraph(const GraphOptions& opt)
    : opt_(opt), cell_m_(float(std::max(0.1, opt.r_e_m))) {
  opt_.k_max = std::clamp(opt_.k_max, 1, GraphNode::kMaxDegree);
}

uint64_t ReachableGraph::cell_key(int32_t x, int32_t y, int32_t z) const {
  constexpr uint64_t m = (uint64_t{1} << 21) - 1;
  return ((uint64_t(uint32_t(x)) & m) << 42) | ((uint64_t(uint32_t(y)) & m) << 21) |
         (uint64_t(uint32_t(z)) & m);
}

uint64_t ReachableGraph::cell_of(const Eigen::Vector3f& p) const {
  return cell_key(int32_t(std::floor(p.x() / cell_m_)), int32_t(std::floor(p.y() / cell_m_)),
                  int32_t(std::floor(p.z() / cell_m_)));
}

void ReachableGraph::nodes_within(const Eigen::Vector3f& p, float r, float dz,
                                  std::vector<NodeId>& out) const {
  const int32_t x0 = int32_t(std::floor((p.x() - r) / cell_m_));
  const int32_t x1 = int32_t(std::floor((p.x() + r) / cell_m_));
  const int32_t y0 = int32_t(std::floor((p.y() - r) / cell_m_));
  const int32_t y1 = int32_t(std::floor((p.y() + r) / cell_m_));
  const int32_t z0 = int32_t(std::floor((p.z() - dz) / cell_m_));
  const int32_t z1 = int32_t(std::floor((p.z() + dz) / cell_m_));
  const float r2 = r * r;
  for (int32_t x = x0; x <= x1; ++x)
    for (int32_t y = y0; y <= y1; ++y)
      for (int32_t z = z0; z <= z1; ++z) {
        auto it = grid_.find(cell_key(x, y, z));
        if (it == grid_.end()) continue;
        for (NodeId n : it->second) {
          const Eigen::Vector3f d = nodes_[n].p_m - p;
          if (d.x() * d.x() + d.y() * d.y() <= r2 && std::abs(d.z()) <= dz) out.push_back(n);
        }
      }
}

NodeId ReachableGraph::nearest(const Eigen::Vector3f& p, float r, float dz) const {
  std::vector<NodeId> near;
  nodes_within(p, r, dz, near);
  NodeId best = kNoId;
  float best_d = std::numeric_limits<float>::infinity();
  for (NodeId n : near) {
    const float d = (nodes_[n].p_m - p).squaredNorm();
    if (d < best_d || (d == best_d && n < best)) {
      best_d = d;
      best = n;
    }
  }
  return best;
}

EdgeId ReachableGraph::find_edge(NodeId a, NodeId b) const {
  const GraphNode& na = nodes_[a];
  for (int k = 0; k < na.degree; ++k)
    if (edges_[na.edges[k]].other(a) == b) return na.edges[k];
  return kNoId;
}

void ReachableGraph::take_touched(std::vector<NodeId>& out) {
  for (NodeId n : touched_) {
    nodes_[n].queued &= ~GraphNode::kTouched;
    if (nodes_[n].alive) out.push_back(n);
  }
  touched_.clear();
}

void ReachableGraph::touch(NodeId i) {
  if (nodes_[i].queued & GraphNode::kTouched) return;
  nodes_[i].queued |= GraphNode::kTouched;
  touched_.push_back(i);
}
void ReachableGraph::queue_expand(NodeId i) {
  if (nodes_[i].queued & GraphNode::kQueuedExpand) return;
  nodes_[i].queued |= GraphNode::kQueuedExpand;
  expand_q_.push_back(i);
}
void ReachableGraph::queue_revalidate(NodeId i) {
  if (nodes_[i].queued & GraphNode::kQueuedRevalidate) return;
  nodes_[i].queued |= GraphNode::kQueuedRevalidate;
  reval_q_.push_back(i);
}

void ReachableGraph::touch_all() {
  for (NodeId i = 0; i < nodes_.size(); ++i)
    if (nodes_[i].alive) {
      queue_revalidate(i);
      queue_expand(i);
    }
}

NodeId ReachableGraph::add_node(const Support& s, bool confirmed) {
  NodeId id;
  if (!free_nodes_.empty()) {
    id = free_nodes_.back();
    free_nodes_.pop_back();
  } else {
    id = NodeId(nodes_.size());
    nodes_.emplace_back();
  }
  GraphNode& n = nodes_[id];
  const uint8_t keep = n.queued & GraphNode::kTouched;  // a stale touched_ entry may remain
  n = GraphNode{};
  n.queued = keep;
  n.p_m = s.p_m;
  n.key = s.key;
  n.state = confirmed ? ElementState::kConfirmed : ElementState::kTentative;
  n.alive = true;
  n.floor_hint = int16_t(std::lround(s.p_m.z() / opt_.floor_height_hint_m));
  grid_[cell_of(n.p_m)].push_back(id);
  ++node_count_;
  touch(id);
  return id;
}

void ReachableGraph::remove_node(NodeId i) {
  GraphNode& n = nodes_[i];
  while (n.degree > 0) remove_edge(n.edges[n.degree - 1]);
  auto it = grid_.find(cell_of(n.p_m));
  if (it != grid_.end()) {
    auto& v = it->second;
    v.erase(std::find(v.begin(), v.end(), i));
    if (v.empty()) grid_.erase(it);
  }
  n.alive = false;
  n.c_sur = n.c_exp = n.boundary = false;
  n.cluster = -1;
  free_nodes_.push_back(i);
  --node_count_;
  if (root_ == i) root_ = kNoId;
  connectivity_lost_ = true;
}

EdgeId ReachableGraph::add_edge(NodeId a, NodeId b, const EdgeCheck& ec) {
  EdgeId id;
  if (!free_edges_.empty()) {
    id = free_edges_.back();
    free_edges_.pop_back();
  } else {
    id = EdgeId(edges_.size());
    edges_.emplace_back();
  }
  GraphEdge& e = edges_[id];
  e.a = a;
  e.b = b;
  e.alive = true;
  e.state = edge_state(a, b, ec);
  e.length_m = ec.length_m;
  e.cost = ec.length_m * (1.0f + ec.mean_cost);
  e.checked = cycle_;
  nodes_[a].edges[nodes_[a].degree++] = id;
  nodes_[b].edges[nodes_[b].degree++] = id;
  ++edge_count_;
  touch(a);
  touch(b);
  return id;
}

void ReachableGraph::remove_edge(EdgeId id) {
  GraphEdge& e = edges_[id];
  for (NodeId n : {e.a, e.b}) {
    GraphNode& gn = nodes_[n];
    for (int k = 0; k < gn.degree; ++k)
      if (gn.edges[k] == id) {
        gn.edges[k] = gn.edges[--gn.degree];
        break;
      }
    touch(n);
  }
  e.alive = false;
  free_edges_.push_back(id);
  --edge_count_;
  connectivity_lost_ = true;
}

ElementState ReachableGraph::edge_state(NodeId a, NodeId b, const EdgeCheck& ec) const {
  return ec.all_reachable && nodes_[a].state == ElementState::kConfirmed &&
                 nodes_[b].state == ElementState::kConfirmed
             ? ElementState::kConfirmed
             : ElementState::kTentative;
}

// alpha_min: a new edge's direction must differ from every existing edge at the endpoint.
bool ReachableGraph::direction_ok(NodeId i, const Eigen::Vector3f& towards) const {
  const GraphNode& n = nodes_[i];
  if (n.degree >= opt_.k_max) return false;
  const Eigen::Vector3f d = towards - n.p_m;
  const float a = std::atan2(d.y(), d.x());
  for (int k = 0; k < n.degree; ++k) {
    const Eigen::Vector3f e = nodes_[edges_[n.edges[k]].other(i)].p_m - n.p_m;
    if (std::abs(wrap_pi(std::atan2(e.y(), e.x()) - a)) < float(opt_.alpha_min_rad)) return false;
  }
  return true;
}

bool ReachableGraph::try_connect(SupportQuery& q, NodeId i, NodeId j, GraphUpdateStats& st) {
  if (i == j || find_edge(i, j) != kNoId) return false;
  if (!direction_ok(i, nodes_[j].p_m) || !direction_ok(j, nodes_[i].p_m)) return false;
  const EdgeCheck ec = q.check_edge(nodes_[i].p_m, nodes_[j].p_m);
  ++st.rejects[int(ec.reject)];
  if (!ec.valid()) return false;
  if (!opt_.use_tentative && edge_state(i, j, ec) != ElementState::kConfirmed) return false;
  add_edge(i, j, ec);
  ++st.edges_added;
  return true;
}

// Re-check one node and its incident edges against the current map (Sec. III-B, incremental
// graph update): promotion into C_reach, demotion, pruning on new obstacles / lost support.
void ReachableGraph::revalidate(SupportQuery& q, NodeId i, GraphUpdateStats& st) {
  GraphNode& n = nodes_[i];
  ++st.revalidated;
  touch(i);
  const std::optional<Support> s = q.support_dilated(n.p_m.x(), n.p_m.y(), n.p_m.z(), q.step());
  bool confirmed = false;
  if (!s || q.classify_node(*s, &confirmed) != Reject::kNone) {
    ++st.nodes_pruned;
    remove_node(i);
    return;
  }
  const ElementState was = n.state;
  // Same column; the surface height may move within a step (the grid cell may change).
  const uint64_t old_cell = cell_of(n.p_m), new_cell = cell_of(s->p_m);
  if (old_cell != new_cell) {
    auto& v = grid_[old_cell];
    v.erase(std::find(v.begin(), v.end(), i));
    if (v.empty()) grid_.erase(old_cell);
    grid_[new_cell].push_back(i);
  }
  n.p_m = s->p_m;
  n.key = s->key;
  n.state = confirmed ? ElementState::kConfirmed : ElementState::kTentative;
  st.promoted += was == ElementState::kTentative && confirmed;
  st.demoted += was == ElementState::kConfirmed && !confirmed;
  for (int k = n.degree - 1; k >= 0; --k) {
    const EdgeId e = n.edges[k];
    const NodeId o = edges_[e].other(i);
    if (edges_[e].checked == cycle_) continue;  // already re-checked from its other end
    edges_[e].checked = cycle_;
    const EdgeCheck ec = q.check_edge(n.p_m, nodes_[o].p_m);
    const ElementState es = ec.valid() ? edge_state(i, o, ec) : ElementState::kTentative;
    if (!ec.valid() || (!opt_.use_tentative && es != ElementState::kConfirmed)) {
      ++st.edges_pruned;
      remove_edge(e);
      continue;
    }
    GraphEdge& ge = edges_[e];
    st.promoted += ge.state == ElementState::kTentative && es == ElementState::kConfirmed;
    st.demoted += ge.state == ElementState::kConfirmed && es == ElementState::kTentative;
    ge.state = es;
    ge.length_m = ec.length_m;
    ge.cost = ec.length_m * (1.0f + ec.mean_cost);
  }
}

// Spatial expansion, Eq. 4: q = p_i + r_e [cos th, sin th, 0], th ~ U(0, 2pi), projected onto
// the local ground. Stratified: sample k draws th uniformly in its own sector of 2pi / n, so the
// n samples cover every direction while each is still uniform.
void ReachableGraph::expand(SupportQuery& q, NodeId i, std::mt19937_64& rng, GraphUpdateStats& st) {
  ++st.expanded;
  const int n = std::max(1, opt_.expansion_samples);
  const float r_e = float(opt_.r_e_m);
  const float window = r_e * float(std::tan(opt_.max_edge_slope_rad)) + q.step();
  const float clearance = float(opt_.node_clearance_m);
  const float nb_r = float(opt_.neighbour_radius_factor) * r_e;
  const double phase = u01(rng);
  for (int k = 0; k < n; ++k) {
    if (!nodes_[i].alive || nodes_[i].degree >= opt_.k_max) break;
    const float th = float(2.0 * M_PI * (double(k) + u01(rng) * 0.999999 + phase) / double(n));
    const Eigen::Vector3f pi = nodes_[i].p_m;
    const Eigen::Vector3f cand = pi + r_e * Eigen::Vector3f(std::cos(th), std::sin(th), 0.0f);
    // An existing node within the clearance of the candidate: connect to it instead.
    NodeId j = nearest(cand, clearance, window);
    if (j != kNoId) {
      try_connect(q, i, j, st);
      continue;
    }
    if (!direction_ok(i, cand)) continue;
    // Local ground: near the node's own level first (one voxel of slack around the column),
    // else the nearest surface within the slope window (stairs, ramps).
    std::optional<Support> s = q.support_dilated(cand.x(), cand.y(), pi.z(), q.step());
    if (!s) {
      s = q.surface_near(cand.x(), cand.y(), pi.z(), window);
      if (s && !s->reachable) s = q.support_dilated(cand.x(), cand.y(), s->p_m.z(), q.step());
    }
    if (!s) {
      ++st.rejects[int(Reject::kNoSupport)];
      continue;
    }
    j = nearest(s->p_m, clearance, q.step());
    if (j != kNoId) {
      try_connect(q, i, j, st);
      continue;
    }
    bool confirmed = false;
    const Reject r = q.classify_node(*s, &confirmed);
    if (r != Reject::kNone) {
      ++st.rejects[int(r)];
      continue;
    }
    const EdgeCheck ec = q.check_edge(pi, s->p_m);
    ++st.rejects[int(ec.reject)];
    if (!ec.valid()) continue;
    if (!opt_.use_tentative &&
        !(ec.all_reachable && confirmed && nodes_[i].state == ElementState::kConfirmed))
      continue;
    j = add_node(*s, confirmed);
    ++st.nodes_added;
    add_edge(i, j, ec);
    ++st.edges_added;
    // Connect the new node to its other reachable neighbours, nearest first.
    scratch_.clear();
    nodes_within(s->p_m, nb_r, window, scratch_);
    std::sort(scratch_.begin(), scratch_.end(), [&](NodeId a, NodeId b) {
      const float da = (nodes_[a].p_m - s->p_m).squaredNorm();
      const float db = (nodes_[b].p_m - s->p_m).squaredNorm();
      return da < db || (da == db && a < b);
    });
    const std::vector<NodeId> near = scratch_;  // try_connect does not touch scratch_
    for (NodeId o : near)
      if (o != i && o != j) try_connect(q, j, o, st);
    queue_expand(j);
  }
}

NodeId ReachableGraph::attach_root(SupportQuery& q, const Eigen::Vector3f& foot,
                                   GraphUpdateStats& st) {
  const float r = float(opt_.root_radius_m);
  NodeId best = nearest(foot, r, q.step());
  std::optional<Support> s;
  if (best != kNoId) {
    const Eigen::Vector3f d = nodes_[best].p_m - foot;
    if (!opt_.root_off_graph || std::abs(d.z()) <= 0.5f * q.step() ||
        d.head<2>().norm() <= float(opt_.node_clearance_m))
      return best;
    s = q.support_dilated(foot.x(), foot.y(), foot.z(), 0.5f * q.step());
    if (!s) return best;
  }
  // The LiDAR cannot see under the body: look for support around the foot too.
  if (!s) s = q.support_dilated(foot.x(), foot.y(), foot.z(), q.step());
  for (int k = 0; k < 8 && !s; ++k) {
    const float a = float(k) * float(M_PI) / 4.0f;
    s = q.support_dilated(foot.x() + 0.5f * r * std::cos(a), foot.y() + 0.5f * r * std::sin(a),
                          foot.z(), q.step());
  }
  if (!s) return kNoId;
  bool confirmed = false;
  if (q.classify_node(*s, &confirmed) != Reject::kNone) return best;
  const NodeId id = add_node(*s, confirmed);
  ++st.nodes_added;
  scratch_.clear();
  const float window = float(opt_.r_e_m * std::tan(opt_.max_edge_slope_rad)) + q.step();
  nodes_within(s->p_m, float(opt_.neighbour_radius_factor * opt_.r_e_m), window, scratch_);
  std::sort(scratch_.begin(), scratch_.end(), [&](NodeId a, NodeId b) {
    const float da = (nodes_[a].p_m - s->p_m).squaredNorm();
    const float db = (nodes_[b].p_m - s->p_m).squaredNorm();
    return da < db || (da == db && a < b);
  });
  const std::vector<NodeId> near = scratch_;
  for (NodeId o : near)
    if (o != id) try_connect(q, id, o, st);
  queue_expand(id);
  return id;
}

// After removals: BFS from the robot's node; whatever it does not reach is no longer part of
// the reachable support structure (Sec. III-B). A cut that leaves the robot in the smaller part
// waits GraphOptions::prune_persistence_updates for the link to come back before pruning.
// BFS from the robot's node over G_real: bfs_ holds its component, mark_[i] == mark_epoch_ marks
// it.
void ReachableGraph::mark_root_component() {
  mark_.resize(nodes_.size(), 0);
  if (++mark_epoch_ == 0) {
    std::fill(mark_.begin(), mark_.end(), 0);
    mark_epoch_ = 1;
  }
  bfs_.clear();
  bfs_.push_back(root_);
  mark_[root_] = mark_epoch_;
  for (size_t h = 0; h < bfs_.size(); ++h) {
    const GraphNode& n = nodes_[bfs_[h]];
    for (int k = 0; k < n.degree; ++k) {
      const NodeId o = edges_[n.edges[k]].other(bfs_[h]);
      if (mark_[o] != mark_epoch_) {
        mark_[o] = mark_epoch_;
        bfs_.push_back(o);
      }
    }
  }
}

void ReachableGraph::prune_disconnected(GraphUpdateStats& st) {
  if (root_ == kNoId) return;
  if (nodes_[root_].degree == 0 && node_count_ > 1) {
    st.root_isolated = true;
    return;
  }
  mark_root_component();
  // Cut off, but still in C_reach (GraphOptions::keep_reachable_cut): kept.
  auto cut = [&](NodeId i) {
    return nodes_[i].alive && mark_[i] != mark_epoch_ &&
           !(opt_.keep_reachable_cut && nodes_[i].state == ElementState::kConfirmed);
  };
  size_t n_cut = 0;
  for (NodeId i = 0; i < nodes_.size(); ++i) n_cut += cut(i);
  if (n_cut == 0) {
    deferred_updates_ = 0;
    return;
  }
  if (2 * bfs_.size() < node_count_ && deferred_updates_ < opt_.prune_persistence_updates) {
    ++deferred_updates_;
    st.prune_deferred = true;
    return;
  }
  deferred_updates_ = 0;
  for (NodeId i = 0; i < nodes_.size(); ++i)
    if (cut(i)) {
      remove_node(i);
      ++st.disconnected;
    }
}

// GraphOptions::relink_cuts: the closest node pairs across a cut of G_real, tried as an edge, and
// (the four closest) through a new node between them, shifted across the pair's line: a 0.9 m
// door leaves the body's 0.3 m half width a few centimetres either side of its middle, which a
// straight edge between two nodes placed by Eq. 4's random expansion rarely passes.
void ReachableGraph::relink_cut(SupportQuery& q, GraphUpdateStats& st) {
  mark_root_component();
  if (bfs_.size() >= node_count_) return;  // one component
  const float r = float(opt_.neighbour_radius_factor * opt_.r_e_m);
  const float window = float(opt_.r_e_m * std::tan(opt_.max_edge_slope_rad)) + q.step();
  bridges_.clear();
  for (NodeId i : bfs_) {
    if (nodes_[i].degree >= opt_.k_max) continue;
    scratch_.clear();
    nodes_within(nodes_[i].p_m, r, window, scratch_);
    for (NodeId j : scratch_)
      if (nodes_[j].alive && mark_[j] != mark_epoch_ && nodes_[j].degree < opt_.k_max)
        bridges_.push_back({(nodes_[i].p_m - nodes_[j].p_m).squaredNorm(), {i, j}});
  }
  std::sort(bridges_.begin(), bridges_.end());
  auto accept = [&](NodeId a, NodeId b, const EdgeCheck& ec) {
    return ec.valid() && (opt_.use_tentative || edge_state(a, b, ec) == ElementState::kConfirmed);
  };
  int tries = 0;
  for (const auto& [d2, ij] : bridges_) {
    if (tries++ >= opt_.relink_tries) break;
    const auto [i, j] = ij;
    if (nodes_[i].degree >= opt_.k_max || nodes_[j].degree >= opt_.k_max) continue;
    const EdgeCheck ec = q.check_edge(nodes_[i].p_m, nodes_[j].p_m);
    if (accept(i, j, ec)) {
      add_edge(i, j, ec);
      ++st.edges_added;
      ++st.relinked;
      return;  // the parts are one; any other cut waits for the next second
    }
    if (tries > 4) continue;
    const Eigen::Vector3f a = nodes_[i].p_m, b = nodes_[j].p_m;
    const Eigen::Vector2f d = (b - a).head<2>();
    if (d.norm() < 1e-3f) continue;
    const Eigen::Vector2f lat = Eigen::Vector2f(-d.y(), d.x()).normalized();
    for (int k = 0; k <= 16; ++k) {
      const float off = 0.05f * float((k + 1) / 2) * (k % 2 ? 1.0f : -1.0f);  // 0, +-0.05, ...
      const Eigen::Vector3f m = 0.5f * (a + b) + off * Eigen::Vector3f(lat.x(), lat.y(), 0.0f);
      const std::optional<Support> s = q.support_dilated(m.x(), m.y(), m.z(), q.step());
      bool confirmed = false;
      if (!s || q.classify_node(*s, &confirmed) != Reject::kNone) continue;
      const EdgeCheck e1 = q.check_edge(a, s->p_m), e2 = q.check_edge(s->p_m, b);
      if (!e1.valid() || !e2.valid()) continue;
      const NodeId mid = add_node(*s, confirmed);
      ++st.nodes_added;
      if (!accept(i, mid, e1) || !accept(mid, j, e2)) {  // the node's own state decides
        remove_node(mid);
        continue;
      }
      add_edge(i, mid, e1);
      add_edge(mid, j, e2);
      st.edges_added += 2;
      st.relinked += 2;
      queue_expand(mid);
      return;
    }
  }
}

GraphUpdateStats ReachableGraph::update(const map::MapView& view, const Eigen::Vector3f& foot,
                                        std::span<const Aabb> changed, std::mt19937_64& rng) {
  GraphUpdateStats st;
  SupportQuery q(view, opt_);
  connectivity_lost_ = false;
  ++cycle_;
  // 1. The affected subgraph: nodes in the changed regions inflated by the reach of their
  //    edges and expansion candidates, nearest to the robot first.
  const float reach = float(opt_.neighbour_radius_factor * opt_.r_e_m);
  boxes_.clear();
  for (const Aabb& b : changed)
    if (!b.empty()) boxes_.push_back(b.inflated(reach));
  scratch_.clear();
  for (NodeId i = 0; i < nodes_.size(); ++i) {
    const GraphNode& n = nodes_[i];
    if (!n.alive || (n.queued & GraphNode::kQueuedRevalidate)) continue;
    bool in = false;
    for (const Aabb& b : boxes_) in = in || b.contains(n.p_m);
    // Promotion / demotion: C_reach can grow or shrink far from the scan (region growing).
    if (!in) in = q.reachable(n.key) != (n.state == ElementState::kConfirmed);
    if (in) scratch_.push_back(i);
  }
  std::stable_sort(scratch_.begin(), scratch_.end(), [&](NodeId a, NodeId b) {
    return (nodes_[a].p_m - foot).squaredNorm() < (nodes_[b].p_m - foot).squaredNorm();
  });
  for (NodeId i : scratch_) queue_revalidate(i);

  // 2. Revalidate within the budget.
  for (int b = 0; b < opt_.max_revalidations_per_update && !reval_q_.empty(); ++b) {
    const NodeId i = reval_q_.front();
    reval_q_.pop_front();
    nodes_[i].queued &= ~GraphNode::kQueuedRevalidate;
    if (!nodes_[i].alive) continue;
    revalidate(q, i, st);
    // The map changed around it: new support may have appeared within r_e.
    if (nodes_[i].alive && nodes_[i].degree < opt_.k_max) queue_expand(i);
  }

  // 3. The robot's node (created if the robot stands away from the graph).
  root_ = attach_root(q, foot, st);
  st.has_root = root_ != kNoId;

  // 4. Expansion (Eq. 4) within the budget.
  for (int b = 0; b < opt_.max_expansions_per_update && !expand_q_.empty(); ++b) {
    const NodeId i = expand_q_.front();
    expand_q_.pop_front();
    nodes_[i].queued &= ~GraphNode::kQueuedExpand;
    if (nodes_[i].alive) expand(q, i, rng, st);
  }

  // 4b. A cut kept (keep_reachable_cut) is re-linked where an edge across it is valid (every
  //     10th update: once a second at the map task's 10 Hz).
  if (opt_.relink_cuts && root_ != kNoId && cycle_ % 10 == 0) relink_cut(q, st);

  // 5. Components cut off from the robot.
  if (connectivity_lost_ || deferred_updates_ > 0) prune_disconnected(st);
  st.pending_revalidations = uint32_t(reval_q_.size());
  st.pending_expansions = uint32_t(expand_q_.size());
  return st;
}

size_t ReachableGraph::mem_usage() const {
  size_t b = sizeof(*this) + nodes_.capacity() * sizeof(GraphNode) +
             edges_.capacity() * sizeof(GraphEdge) +
             (free_nodes_.capacity() + free_edges_.capacity() + touched_.capacity() +
              scratch_.capacity() + bfs_.capacity() + mark_.capacity()) *
                 sizeof(uint32_t);
  for (const auto& [k, v] : grid_) b += sizeof(k) + sizeof(v) + v.capacity() * sizeof(NodeId) + 16;
  return b;
}

}  // namespace storey::core::graph
