#include "core/baselines/tare_like_planner.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <tuple>

namespace storey::core::baselines {

bool tare_link_ok(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double threshold_m,
                  double spacing_m) {
  const double dz = std::abs(a.z() - b.z());
  const double h = (a - b).head<2>().norm();
  return dz <= threshold_m && dz <= threshold_m * std::max(h, 1e-3) / spacing_m + 1e-9;
}

bool tare_path_ok(const std::vector<Eigen::Vector3d>& path_m, double threshold_m,
                  double spacing_m) {
  // Windows of about spacing_m along the path (two-pointer walk).
  size_t j = 0;
  for (size_t i = 0; i < path_m.size(); ++i) {
    if (j < i) j = i;
    while (j + 1 < path_m.size() && (path_m[j] - path_m[i]).head<2>().norm() < spacing_m) ++j;
    if (j > i && !tare_link_ok(path_m[i], path_m[j], threshold_m, spacing_m)) {
      // A short window at the path's end: judge it by the rule's gradient only.
      return false;
    }
  }
  return true;
}

uint32_t largest_part_start(const plan::SearchGraph& sg, std::span<const uint32_t> starts,
                            plan::GraphSearch& search) {
  uint32_t best = UINT32_MAX;
  size_t best_size = 0;
  std::vector<size_t> size(starts.size(), 0);  // 0: not measured yet
  for (size_t i = 0; i < starts.size(); ++i) {
    if (starts[i] >= sg.num_nodes() || size[i] != 0) continue;
    const size_t n = search.dijkstra(sg, starts.subspan(i, 1)).size();
    for (size_t j = i; j < starts.size(); ++j)  // the same part: measured with it
      if (size[j] == 0 && std::isfinite(search.dist(starts[j]))) size[j] = n;
    if (n > best_size) best_size = n, best = starts[i];
  }
  return best;
}

TareLikePlanner::TareLikePlanner(const RobotModel& robot, const plan::PlanOptions& plan,
                                 double voxel_size_m, const BaselineOptions& options)
    : opt_(options),
      driver_(robot, plan, voxel_size_m, options),
      tsp_(plan::TspOptions{plan.tsp_exact_max_n}) {
  // Its goals stand at a cluster's viewpoint; key_m is the frontier node, a place to stand.
  driver_.set_approach_frontier(true);
  const double th = options.height_threshold_m, sp = options.link_spacing_m;
  driver_.set_path_filter(
      [th, sp](const std::vector<Eigen::Vector3d>& p) { return tare_path_ok(p, th, sp); });
  // Its own viewpoint graph (this cycle's, built by goals()) where the voxel A* finds no path.
  driver_.set_fallback_path([this](const plan::ExplorationInput& in, const Goal& goal) {
    std::vector<Eigen::Vector3d> path;
    if (robot_node_ >= sg_.num_nodes() || goal.node >= sg_.num_nodes()) return path;
    const plan::PathResult r = path_search_.astar(sg_, robot_node_, goal.node);
    if (!r.found) return path;
    path.push_back(in.robot_foot_m);
    for (uint32_t u : r.nodes) path.push_back(sg_.position(u));
    if ((path.back() - goal.p_m).norm() > 1e-6) path.push_back(goal.p_m);
    return path;
  });
}

std::vector<Goal> TareLikePlanner::goals(const plan::ExplorationInput& in) {
  std::vector<Goal> out;
  const graph::ReachableGraph& g = *in.graph;
  // Viewpoint graph: G_real's nodes, its real edges that pass the height rule.
  std::vector<Eigen::Vector3d> pos(g.node_capacity(), Eigen::Vector3d::Zero());
  for (graph::NodeId i = 0; i < g.node_capacity(); ++i)
    if (g.node(i).alive) pos[i] = g.node(i).p_m.cast<double>();
  std::vector<plan::SearchGraph::Edge> edges;
  kept_ = refused_ = 0;
  for (graph::EdgeId e = 0; e < g.edge_capacity(); ++e) {
    const graph::GraphEdge& ge = g.edge(e);
    if (!ge.alive || ge.state == graph::ElementState::kHypothetical) continue;
    if (!tare_link_ok(pos[ge.a], pos[ge.b], opt_.height_threshold_m, opt_.link_spacing_m)) {
      ++refused_;
      continue;
    }
    ++kept_;
    edges.push_back({ge.a, ge.b, double(std::max(ge.cost, ge.length_m))});
  }
  sg_ = plan::SearchGraph::from_edges(pos, edges, true);
  robot_node_ = UINT32_MAX;
  // The robot's node: among the root and the linked nodes within 1.5 m (nearest first), the one
  // whose part of the viewpoint graph is largest. A root with no link reached no cluster and the
  // run ended "stranded" at 61 s, 27.9 % (office seed 4); a root linked only to one other node,
  // on top of the ramp, ended "stranded" at 444 s (maze seed 2).
  std::vector<uint8_t> linked(pos.size(), 0);
  for (const plan::SearchGraph::Edge& e : edges) linked[e.from] = linked[e.to] = 1;
  near_.clear();
  g.nodes_within(in.robot_foot_m.cast<float>(), 1.5f, 1.0f, near_);
  const Eigen::Vector3f foot = in.robot_foot_m.cast<float>();
  std::sort(near_.begin(), near_.end(), [&](graph::NodeId a, graph::NodeId b) {
    const float da = (g.node(a).p_m - foot).squaredNorm(),
                db = (g.node(b).p_m - foot).squaredNorm();
    return da < db || (da == db && a < b);
  });
  std::vector<uint32_t> starts;
  const graph::NodeId root = g.root();
  if (root != graph::kNoId && g.node(root).alive && linked[root]) starts.push_back(root);
  for (graph::NodeId n : near_)
    if (n != root && g.node(n).alive && linked[n]) starts.push_back(n);
  uint32_t robot = largest_part_start(sg_, starts, search_);
  if (robot == UINT32_MAX) {
    if (root != graph::kNoId && g.node(root).alive)
      robot = root;
    else
      robot = g.nearest(foot, 1.5f, 1.0f);
  }
  if (robot == graph::kNoId) return out;
  robot_node_ = robot;
  search_.dijkstra(sg_, std::span<const uint32_t>(&robot, 1));

  // Reachable clusters: representative = reachable member nearest the centroid.
  struct Cand {
    size_t ci;
    uint32_t rep;
    double d;
    std::tuple<int, int, int> cell;
  };
  std::vector<Cand> cands;
  const double cell = opt_.global_cell_m;
  for (size_t ci = 0; ci < in.clusters->size(); ++ci) {
    const graph::FrontierCluster& c = (*in.clusters)[ci];
    uint32_t rep = graph::kNoId;
    float best = std::numeric_limits<float>::infinity();
    for (graph::NodeId n : c.nodes) {
      if (!std::isfinite(search_.dist(n)) || driver_.set_aside(pos[n])) continue;
      const float d = (g.node(n).p_m - c.centroid_m).squaredNorm();
      if (d < best) best = d, rep = n;
    }
    if (rep == graph::kNoId) continue;
    const Eigen::Vector3d p = pos[rep];
    cands.push_back({ci,
                     rep,
                     search_.dist(rep),
                     {int(std::floor(p.x() / cell)), int(std::floor(p.y() / cell)),
                      int(std::lround(p.z() / 3.0))}});
  }
  if (cands.empty()) return out;
  // Global layer: subspaces with work, ordered by an open TSP from the robot.
  std::map<std::tuple<int, int, int>, std::vector<size_t>> cells;
  for (size_t i = 0; i < cands.size(); ++i) cells[cands[i].cell].push_back(i);
  std::vector<uint32_t> reps{robot};
  std::vector<std::vector<size_t>> members;
  for (auto& [key, idx] : cells) {
    // The subspace's representative: its member nearest the robot along the graph.
    size_t b = idx.front();
    for (size_t i : idx)
      if (cands[i].d < cands[b].d) b = i;
    reps.push_back(cands[b].rep);
    members.push_back(idx);
  }
  const int n = int(reps.size());
  std::vector<double> cost(size_t(n) * size_t(n), 0.0);
  for (int i = 0; i < n; ++i)
    search_.costs_from(sg_, reps[size_t(i)], reps,
                       std::span<double>(cost.data() + size_t(i) * size_t(n), size_t(n)));
  const plan::TspResult tour = tsp_.solve(plan::CostMatrix{n, cost}, 0);
  std::vector<int> order;
  if (tour.status == plan::TspStatus::kOk)
    for (int k : tour.order)
      if (k > 0) order.push_back(k - 1);
  if (order.size() != members.size()) {
    order.clear();
    for (int k = 0; k < int(members.size()); ++k) order.push_back(k);
  }
  // Local layer: clusters of the first subspace by graph distance, then the following ones.
  search_.dijkstra(sg_, std::span<const uint32_t>(&robot, 1));
  double rank = 0;
  for (int m : order) {
    std::vector<size_t> idx = members[size_t(m)];
    std::stable_sort(idx.begin(), idx.end(),
                     [&](size_t a, size_t b) { return cands[a].d < cands[b].d; });
    for (size_t i : idx) {
      const Cand& c = cands[i];
      const graph::FrontierCluster& fc = (*in.clusters)[c.ci];
      Goal goal;
      goal.key_m = pos[c.rep];
      goal.p_m = pos[c.rep];
      goal.node = c.rep;
      Eigen::Vector3d look = fc.centroid_m.cast<double>() - goal.p_m;
      for (const graph::ClusterViewpoints& cv : *in.viewpoints) {
        if (cv.cluster_id != fc.id) continue;
        // The first viewpoint not set aside (else the frontier node itself): the cluster's first
        // viewpoint, set aside after its trajectories collided, made every later goal of the
        // cluster a set-aside one and the run ended "complete" at 19.5 s (maze seed 5).
        for (const graph::Viewpoint& v : cv.viewpoints)
          if (v.node < g.node_capacity() && g.node(v.node).alive &&
              std::isfinite(search_.dist(v.node)) && !driver_.set_aside(v.p_m.cast<double>())) {
            goal.p_m = v.p_m.cast<double>();
            goal.node = v.node;
            look = Eigen::Vector3d(std::cos(v.yaw_rad), std::sin(v.yaw_rad), 0);
            break;
          }
      }
      goal.yaw_rad = look.head<2>().norm() > 1e-6 ? std::atan2(look.y(), look.x()) : 0.0;
      goal.cost = rank++;
      out.push_back(std::move(goal));
    }
  }
  return out;
}

plan::ExplorationResult TareLikePlanner::plan(const plan::ExplorationInput& in) {
  plan::ExplorationResult r;
  if (!in.view || !in.graph || !in.clusters || !in.viewpoints || !in.robot_foot_m.allFinite() ||
      !std::isfinite(in.t_s)) {
    r.reason = "bad input (null pointer or non-finite pose/time)";
    return r;
  }
  std::vector<Goal> gs = goals(in);
  if (gs.empty() && (in.graph->root() == graph::kNoId && in.graph->node_count() == 0)) {
    r.status = plan::ExplorationStatus::kExploring;
    r.reason = "no graph node at the robot yet";
    return r;
  }
  if (driver_.keep(in, gs, r)) return r;
  driver_.choose(in, gs, r);
  return r;
}

}  // namespace storey::core::baselines
