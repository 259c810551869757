#pragma once
// Shortest paths on a sparse weighted graph given as adjacency: Dijkstra, bounded Dijkstra (task
// zones, paper Sec. IV-A), A* and the two-stage A* of Sec. IV-C (real elements first, then the
// hybrid graph), plus the "real prefix" rule for execution toward hypothetical space.
//
// The graph is any type with the Adjacency shape below; SearchGraph is a small CSR that has it.
// Adjacency concept:
//   size_t num_nodes() const;
//   Eigen::Vector3d position(uint32_t u) const;                     // [m], for the A* heuristic
//   template <class F> void for_each_edge(uint32_t u, F&& f) const;  // f(v, weight, edge_id)
// Edge filters are callables bool(uint32_t edge_id, uint32_t from, uint32_t to); pass
// AllEdges{} for none. Weights must be >= 0; A* needs weight >= straight-line distance times
// the heuristic weight for optimality (true for path lengths on the graph).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <span>
#include <utility>
#include <vector>

#include <Eigen/Core>

namespace storey::core::plan {

inline constexpr uint32_t kNoNode = 0xFFFFFFFFu;
inline constexpr double kUnreachable = std::numeric_limits<double>::infinity();

struct AllEdges {
  bool operator()(uint32_t, uint32_t, uint32_t) const { return true; }
};

// Compressed sparse rows: the edges of u are [offsets[u], offsets[u+1]) in targets/weights; the
// edge id is that index. Undirected graphs store each edge twice (one id per direction).
struct SearchGraph {
  std::vector<Eigen::Vector3d> positions_m;
  std::vector<uint32_t> offsets{0};
  std::vector<uint32_t> targets;
  std::vector<double> weights;

  struct Edge {
    uint32_t from, to;
    double weight;
  };
  // Builds the CSR from an edge list (stable: edges keep their input order per node). Edges with
  // an endpoint out of range or a negative/NaN weight are dropped and counted in *dropped.
  static SearchGraph from_edges(std::span<const Eigen::Vector3d> positions,
                                std::span<const Edge> edges, bool undirected,
                                size_t* dropped = nullptr);

  size_t num_nodes() const { return positions_m.size(); }
  size_t num_edges() const { return targets.size(); }
  Eigen::Vector3d position(uint32_t u) const { return positions_m[u]; }
  template <class F>
  void for_each_edge(uint32_t u, F&& f) const {
    for (uint32_t e = offsets[u]; e < offsets[u + 1]; ++e) f(targets[e], weights[e], e);
  }
};

struct PathResult {
  bool found = false;
  double cost = kUnreachable;
  std::vector<uint32_t> nodes;  // start ... goal
  uint32_t expansions = 0;
};

struct TwoStageResult : PathResult {
  bool used_hybrid = false;  // stage 1 (real elements only) failed; the path may use hypotheses
};

// One settled node of a (bounded) Dijkstra.
struct Settled {
  uint32_t node;
  double dist;
  uint32_t pred;  // kNoNode for a source
};

// Reusable search state. Scratch arrays grow to the largest graph seen and are then reused
// (no allocation per search once grown); a generation stamp marks which entries are current.
class GraphSearch {
 public:
  double heuristic_weight = 1.0;  // A* h = weight * straight-line distance (0: Dijkstra order)

  // A* from start to goal through edges accepted by `filter`.
  template <class Adj, class Filter = AllEdges>
  PathResult astar(const Adj& g, uint32_t start, uint32_t goal, Filter&& filter = {});

  // Two-stage A* (paper Sec. IV-C): first only edges with is_real(edge, from, to) (both the edge
  // and its endpoints real, as the caller defines it), then, if that fails, every edge.
  template <class Adj, class IsReal>
  TwoStageResult two_stage_astar(const Adj& g, uint32_t start, uint32_t goal, IsReal&& is_real) {
    TwoStageResult r;
    static_cast<PathResult&>(r) = astar(g, start, goal, is_real);
    if (r.found) return r;
    const uint32_t first = r.expansions;
    static_cast<PathResult&>(r) = astar(g, start, goal, AllEdges{});
    r.expansions += first;
    r.used_hybrid = r.found;
    return r;
  }

  // Dijkstra from `sources` (distance 0 each), settling nodes in order of distance up to
  // radius_m (inclusive; +inf: unbounded). Returns the settled nodes; valid until the next call.
  // If `stop_at` is non-empty the search ends once all of them are settled.
  template <class Adj, class Filter = AllEdges>
  std::span<const Settled> dijkstra(const Adj& g, std::span<const uint32_t> sources,
                                    double radius_m = kUnreachable, Filter&& filter = {},
                                    std::span<const uint32_t> stop_at = {});

  // Path costs from `source` to each of `targets` (kUnreachable if none): one Dijkstra, for the
  // TSP cost rows D_ij of Sec. IV-C / IV-D.
  template <class Adj, class Filter = AllEdges>
  void costs_from(const Adj& g, uint32_t source, std::span<const uint32_t> targets,
                  std::span<double> out, Filter&& filter = {}) {
    dijkstra(g, std::span<const uint32_t>(&source, 1), kUnreachable, filter, targets);
    for (size_t i = 0; i < targets.size(); ++i) out[i] = dist(targets[i]);
  }

  // Results of the last search: distance (kUnreachable if not settled/reached) and predecessor.
  double dist(uint32_t u) const {
    return u < stamp_.size() && stamp_[u] == gen_ ? dist_[u] : kUnreachable;
  }
  uint32_t pred(uint32_t u) const {
    return u < stamp_.size() && stamp_[u] == gen_ ? pred_[u] : kNoNode;
  }
  // Node path from a source of the last search to u (empty if u was not reached).
  void path_to(uint32_t u, std::vector<uint32_t>& out) const;

 private:
  struct HeapItem {
    double key;
    uint32_t node;
    bool operator>(const HeapItem& o) const {
      return key > o.key || (key == o.key && node > o.node);  // deterministic ties
    }
  };
  void reset(size_t n);
  void push(double key, uint32_t u);
  HeapItem pop();

  std::vector<double> dist_;
  std::vector<uint32_t> pred_, stamp_, closed_;
  std::vector<std::pair<uint32_t, uint32_t>> target_;  // (generation, multiplicity) of stop_at
  std::vector<HeapItem> heap_;
  std::vector<Settled> settled_;
  uint32_t gen_ = 0;
};

// Execution toward hypothetical space follows only the real prefix of a path (paper Sec. IV-C):
// the number of leading nodes of `path` for which is_real(node) holds.
template <class IsRealNode>
size_t real_prefix_length(std::span<const uint32_t> path, IsRealNode&& is_real) {
  size_t k = 0;
  while (k < path.size() && is_real(path[k])) ++k;
  return k;
}

// ----- implementation -----

inline void GraphSearch::reset(size_t n) {
  if (stamp_.size() < n) {
    dist_.resize(n);
    pred_.resize(n);
    stamp_.resize(n, 0);
    closed_.resize(n, 0);
  }
  if (++gen_ == 0) {  // wrapped: clear stamps once every 2^32 searches
    std::fill(stamp_.begin(), stamp_.end(), 0);
    std::fill(closed_.begin(), closed_.end(), 0);
    std::fill(target_.begin(), target_.end(), std::pair<uint32_t, uint32_t>{0, 0});
    gen_ = 1;
  }
  heap_.clear();
  settled_.clear();
}

inline void GraphSearch::push(double key, uint32_t u) {
  heap_.push_back({key, u});
  std::push_heap(heap_.begin(), heap_.end(), std::greater<HeapItem>());
}

inline GraphSearch::HeapItem GraphSearch::pop() {
  std::pop_heap(heap_.begin(), heap_.end(), std::greater<HeapItem>());
  const HeapItem h = heap_.back();
  heap_.pop_back();
  return h;
}

inline void GraphSearch::path_to(uint32_t u, std::vector<uint32_t>& out) const {
  out.clear();
  if (dist(u) == kUnreachable) return;
  for (uint32_t v = u; v != kNoNode; v = pred_[v]) out.push_back(v);
  std::reverse(out.begin(), out.end());
}

template <class Adj, class Filter>
PathResult GraphSearch::astar(const Adj& g, uint32_t start, uint32_t goal, Filter&& filter) {
  PathResult r;
  const size_t n = g.num_nodes();
  if (start >= n || goal >= n) return r;
  reset(n);
  const Eigen::Vector3d goal_p = g.position(goal);
  auto h = [&](uint32_t u) { return heuristic_weight * (g.position(u) - goal_p).norm(); };
  stamp_[start] = gen_;
  dist_[start] = 0;
  pred_[start] = kNoNode;
  push(h(start), start);
  while (!heap_.empty()) {
    const HeapItem top = pop();
    const uint32_t u = top.node;
    if (closed_[u] == gen_) continue;
    closed_[u] = gen_;
    ++r.expansions;
    if (u == goal) {
      r.found = true;
      r.cost = dist_[u];
      path_to(u, r.nodes);
      return r;
    }
    const double du = dist_[u];
    g.for_each_edge(u, [&](uint32_t v, double w, uint32_t e) {
      if (closed_[v] == gen_ || !filter(e, u, v)) return;
      const double nd = du + w;
      if (stamp_[v] != gen_ || nd < dist_[v]) {
        stamp_[v] = gen_;
        dist_[v] = nd;
        pred_[v] = u;
        push(nd + h(v), v);
      }
    });
  }
  return r;
}

template <class Adj, class Filter>
std::span<const Settled> GraphSearch::dijkstra(const Adj& g, std::span<const uint32_t> sources,
                                               double radius_m, Filter&& filter,
                                               std::span<const uint32_t> stop_at) {
  const size_t n = g.num_nodes();
  reset(n);
  for (uint32_t s : sources) {
    if (s >= n || stamp_[s] == gen_) continue;
    stamp_[s] = gen_;
    dist_[s] = 0;
    pred_[s] = kNoNode;
    push(0, s);
  }
  // Targets are marked (target_[t] == gen_, with their multiplicity) so settling a node costs
  // O(1) instead of a pass over stop_at (the global planner passes ~100 zone centres).
  size_t remaining = 0;
  if (target_.size() < n) target_.resize(n, {0, 0});
  for (uint32_t t : stop_at) {
    if (t >= n) continue;
    if (target_[t].first != gen_) target_[t] = {gen_, 0};
    ++target_[t].second;  // a duplicate is counted and settled twice
    ++remaining;
  }
  while (!heap_.empty()) {
    const HeapItem top = pop();
    const uint32_t u = top.node;
    if (closed_[u] == gen_) continue;
    if (top.key > radius_m) break;
    closed_[u] = gen_;
    settled_.push_back({u, dist_[u], pred_[u]});
    if (!stop_at.empty() && target_[u].first == gen_) {
      remaining -= target_[u].second;
      if (remaining == 0) break;
    }
    const double du = dist_[u];
    g.for_each_edge(u, [&](uint32_t v, double w, uint32_t e) {
      if (closed_[v] == gen_ || !filter(e, u, v)) return;
      const double nd = du + w;
      if (nd > radius_m) return;
      if (stamp_[v] != gen_ || nd < dist_[v]) {
        stamp_[v] = gen_;
        dist_[v] = nd;
        pred_[v] = u;
        push(nd, v);
      }
    });
  }
  // Nodes reached but not settled (beyond the radius or after an early stop) must not report a
  // tentative distance: only settled nodes count.
  for (const HeapItem& hi : heap_)
    if (closed_[hi.node] != gen_) stamp_[hi.node] = gen_ - 1;
  return settled_;
}

}  // namespace storey::core::plan
