#include "core/plan/local_planner.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include "core/plan/path_centring.hpp"
#include "core/plan/plan_config.hpp"

namespace storey::core::plan {

// Climbs tried near a deferred climb that found no flight before it is given up (flight_foot).
constexpr int kMaxDeferredClimbMisses = 4;

const char* to_string(LocalPlanStatus s) {
  switch (s) {
    case LocalPlanStatus::kNewTrajectory:
      return "new_trajectory";
    case LocalPlanStatus::kKeep:
      return "keep";
    case LocalPlanStatus::kNoFrontiers:
      return "no_frontiers";
    case LocalPlanStatus::kNoReachableTarget:
      return "no_reachable_target";
    case LocalPlanStatus::kNoRobotNode:
      return "no_robot_node";
    case LocalPlanStatus::kStartBlocked:
      return "start_blocked";
    case LocalPlanStatus::kBadInput:
      return "bad_input";
    case LocalPlanStatus::kSearching:
      return "searching";
    case LocalPlanStatus::kSettling:
      return "settling";
  }
  return "unknown";
}

const char* to_string(SetAsideReason r) {
  switch (r) {
    case SetAsideReason::kStillFrontierAtTarget:
      return "still_frontier_at_target";
    case SetAsideReason::kOverdue:
      return "target_overdue";
    case SetAsideReason::kAstarFailed:
      return "astar_failed";
    case SetAsideReason::kTrajectoryFailed:
      return "trajectory_failed";
  }
  return "unknown";
}

// Target momentum: the tour re-solved at a periodic replan from a few metres further on often
// starts at another cluster of nearly the same total cost (the two ways round a loop, two ends
// of a corridor). Turning to it and back again at the next replan wastes both (test_ramp: the
// robot turned back and forth at the loop's east end). The current target `kept` (index into the
// TSP's clusters, matrix index kept + 1) stays first unless the new tour is shorter by the margin.
void keep_first_in_tour(size_t kept, const std::vector<double>& cost, int n, bool with_anchor,
                        double margin_m, double margin_frac, std::vector<size_t>& order) {
  if (order.empty() || order.front() == kept) return;
  auto tour_cost = [&](const std::vector<size_t>& o) {
    double c = 0;
    size_t at = 0;
    for (size_t k : o) c += cost[at * size_t(n) + k + 1], at = k + 1;
    if (with_anchor) c += cost[at * size_t(n) + size_t(n - 1)];
    return c;
  };
  std::vector<size_t> alt{kept};
  for (size_t k : order)
    if (k != kept) alt.push_back(k);
  if (alt.size() != order.size()) return;  // kept is not in the tour
  const double c_new = tour_cost(order);
  if (tour_cost(alt) <= c_new + std::max(margin_m, margin_frac * c_new)) order = std::move(alt);
}

LocalPlanner::LocalPlanner(const RobotModel& robot, const PlanOptions& plan, double voxel_size_m,
                           const LocalPlannerOptions& options)
    : robot_(robot),
      plan_opt_(plan),
      opt_(options),
      tsp_(tsp_options(plan)),
      dp_(dp_options(plan)),
      astar_(astar_options(plan)),
      builder_(robot, trajectory_options(plan)),
      checker_(robot, voxel_size_m) {}

const SetAsideEntry* LocalPlanner::set_aside_at(const Eigen::Vector3f& p) const {
  const float r2 = float(opt_.set_aside_radius_m * opt_.set_aside_radius_m);
  for (const SetAsideEntry& e : set_aside_)
    if ((p.head<2>() - e.p_m.head<2>()).squaredNorm() <= r2 && std::abs(p.z() - e.p_m.z()) < 0.5f)
      return &e;
  return nullptr;
}

uint16_t frontier_signature(const graph::GraphNode& n) {
  return uint16_t(n.c_sur | (n.c_exp << 1) | (n.boundary << 2) | (uint16_t(n.open_dirs) << 3));
}

void LocalPlanner::set_aside_cluster(const LocalPlanInput& in, const graph::FrontierCluster& c,
                                     SetAsideReason reason, const Eigen::Vector3f& hit_m) {
  const graph::ReachableGraph& g = *in.graph;
  const float r = float(opt_.track_radius_m);
  // The largest count of a place near p (a frontier set aside here before keeps its counts).
  auto count_near = [r](const std::vector<Retried>& places, const Eigen::Vector3f& p) {
    int k = 0;
    for (const Retried& q : places)
      if ((q.p_m - p).head<2>().norm() <= r && std::abs(q.p_m.z() - p.z()) < 0.5f)
        k = std::max(k, q.retries);
    return k;
  };
  constexpr float kSamePlaceM = 0.1f;  // a node re-sampled this close is the same place
  const bool unresolved =
      plan_opt_.set_aside_backoff &&
      (reason == SetAsideReason::kStillFrontierAtTarget || reason == SetAsideReason::kOverdue);
  unresolved_new_.clear();
  for (graph::NodeId n : c.nodes) {
    const Eigen::Vector3f p = g.node(n).p_m;
    const int k = unresolved ? count_near(unresolved_, p) : 0;  // set aside unresolved before
    set_aside_.push_back({p, in.t_s, c.id, reason, in.robot_foot_m.cast<float>(),
                          frontier_signature(g.node(n)), hit_m, count_near(retried_, p), false,
                          opt_.set_aside_expiry_s * double(1 << std::min(4, k))});
    if (unresolved) unresolved_new_.push_back({p, k + 1});
  }
  // Recorded after the lookups (a cluster's nodes lie close together); one entry per place.
  for (const Retried& q : unresolved_new_) {
    auto same = std::find_if(unresolved_.begin(), unresolved_.end(), [&](const Retried& o) {
      return (o.p_m - q.p_m).squaredNorm() < kSamePlaceM * kSamePlaceM;
    });
    if (same != unresolved_.end())
      same->retries = std::max(same->retries, q.retries);
    else
      unresolved_.push_back(q);
  }
}

// A set-aside node means "not resolvable from where the robot can stand, on the map as it was
// then". It expires when that premise may no longer hold:
//  1) the map near it changed: no live node within set_aside_radius_m any more, or the nearest
//     one moved, is no frontier, or has other frontier flags than then (TopologicalFrontiers
//     recomputes them where the map changed);
//  2) its expiry_s (set_aside_expiry_s, with set_aside_backoff longer where frontiers were set
//     aside unresolved before) passed and the robot is more than set_aside_expiry_move_m from
//     where it stood then: another vantage point may resolve it.
// Only inputs decide (t_s is the input's time base, no clock), so replays repeat it.
int LocalPlanner::expire_set_aside(const LocalPlanInput& in) {
  constexpr float kMovedM = 0.05f;  // a node this far from its recorded position was re-sampled
  const graph::ReachableGraph& g = *in.graph;
  const Eigen::Vector3f robot = in.robot_foot_m.cast<float>();
  const float r = float(opt_.set_aside_radius_m);
  const float move2 = float(opt_.set_aside_expiry_move_m * opt_.set_aside_expiry_move_m);
  size_t kept = 0;
  for (size_t i = 0; i < set_aside_.size(); ++i) {
    const SetAsideEntry& e = set_aside_[i];
    near_scratch_.clear();
    g.nodes_within(e.p_m, r, 0.5f, near_scratch_);
    graph::NodeId best = graph::kNoId;
    float best_d = std::numeric_limits<float>::infinity();
    for (graph::NodeId n : near_scratch_) {
      if (!g.node(n).alive) continue;
      const float d = (g.node(n).p_m - e.p_m).squaredNorm();
      if (d < best_d || (d == best_d && n < best)) best_d = d, best = n;
    }
    bool expire = best == graph::kNoId;
    if (!expire) {
      const graph::GraphNode& gn = g.node(best);
      expire =
          !gn.frontier() || frontier_signature(gn) != e.frontier_sig || best_d > kMovedM * kMovedM;
    }
    expire = expire ||
             (in.t_s - e.t_s >= e.expiry_s && (robot - e.robot_m).head<2>().squaredNorm() > move2);
    if (!expire)
      set_aside_[kept++] = e;
    else if (e.retries > 0)
      remember_retried(e);
  }
  const int n = int(set_aside_.size() - kept);
  set_aside_.resize(kept);
  expired_total_ += uint64_t(n);
  return n;
}

// Stage 3 failed for the last clusters from where the robot stands. That is often the robot's
// fault, not the clusters': facing down a ramp too narrow to turn on, by a wall end it cannot
// curve away from (test_ramp: the run ended "complete" with the upper floor unexplored). Before
// the failures end the run, walk to a new vantage point a trajectory reaches (along G_real toward
// the nearest failed frontier first, then any node at least retry_move_m away) and release those
// set-asides when the walk ends.
bool LocalPlanner::retry_from_elsewhere(const LocalPlanInput& in, LocalPlanResult& out) {
  if (!in.last_resort || plan_opt_.path_retries <= 0 || robot_node_ >= sg_.num_nodes())
    return false;
  // Just after a climb the new floor's graph is still growing and its frontiers have no path
  // yet: a retry then went for the failures left below and walked back down the flight
  // (test_stair seed 1, session 22).
  if (climb_done_s_ >= 0 && in.t_s - climb_done_s_ < opt_.climb_settle_s) return false;
  // Which set-asides are retried, decided once (flight_foot searches the map): path failures, and
  // with retry_flight_frontiers still frontiers up a flight or at the foot of one.
  enum Pick : uint8_t { kNo = 0, kPath, kFlight };
  const double flight_rise_m = 2.0 * robot_.step_height_m;
  std::vector<uint8_t> pick(set_aside_.size(), kNo);
  for (size_t i = 0; i < set_aside_.size(); ++i) {
    const SetAsideEntry& e = set_aside_[i];
    if (e.retries >= plan_opt_.path_retries || e.retry_pending) continue;
    if (e.reason == SetAsideReason::kAstarFailed || e.reason == SetAsideReason::kTrajectoryFailed)
      pick[i] = kPath;
    else if (plan_opt_.retry_flight_frontiers &&
             e.reason == SetAsideReason::kStillFrontierAtTarget &&
             (double(e.p_m.z()) - in.robot_foot_m.z() >= flight_rise_m ||
              flight_foot(*in.view, {e.p_m.cast<double>()}, in.robot_foot_m.z())))
      pick[i] = kFlight;
  }
  if (std::none_of(pick.begin(), pick.end(), [](uint8_t k) { return k != kNo; }) || !free_start(in))
    return false;
  const graph::ReachableGraph& g = *in.graph;
  const double r_min = opt_.retry_move_m, d_max = 3.0 * opt_.retry_move_m;
  auto far_enough = [&](graph::NodeId n) {
    return (g.node(n).p_m.cast<double>() - in.robot_foot_m).head<2>().norm() >= r_min;
  };
  // First toward the nearest such frontier along G_real, from retry_near_m short of it back to
  // the robot: the failure often lies in a long path's last turn (into a ramp's walled channel
  // from the corridor beside it), which a start closer by takes with room to spare.
  std::vector<graph::NodeId> cands;
  const SetAsideEntry* nearest = nullptr;
  for (size_t i = 0; i < set_aside_.size(); ++i) {
    const SetAsideEntry& e = set_aside_[i];
    if (pick[i] != kNo &&
        (!nearest || (e.p_m - in.robot_foot_m.cast<float>()).squaredNorm() <
                         (nearest->p_m - in.robot_foot_m.cast<float>()).squaredNorm()))
      nearest = &e;
  }
  const graph::NodeId goal = g.nearest(nearest->p_m, 0.5f, 0.5f);
  if (goal != graph::kNoId && goal < sg_.num_nodes()) {
    const PathResult path = pair_search_.astar(sg_, robot_node_, goal);
    double from_goal = 0;
    for (size_t k = path.nodes.size(); k-- > 1;) {
      if (from_goal >= opt_.retry_near_m && far_enough(path.nodes[k]))
        cands.push_back(path.nodes[k]);
      from_goal += (sg_.position(path.nodes[k]) - sg_.position(path.nodes[k - 1])).norm();
    }
  }
  // Then the nearest nodes at least retry_move_m away, by graph distance, any direction.
  for (const Settled& st : search_.dijkstra(sg_, std::span<const uint32_t>(&robot_node_, 1), d_max))
    if (far_enough(st.node)) cands.push_back(st.node);
  std::vector<Eigen::Vector3d> tried;  // one try per direction: a failed one's neighbours fail too
  for (graph::NodeId n : cands) {
    if (int(tried.size()) >= opt_.max_retry_vantages) break;
    const Eigen::Vector3d p = g.node(n).p_m.cast<double>();
    if (std::any_of(tried.begin(), tried.end(),
                    [&](const Eigen::Vector3d& q) { return (q - p).norm() < 1.0; }))
      continue;
    tried.push_back(p);
    const Eigen::Vector2d dir = (p - in.robot_foot_m).head<2>();
    SetAsideReason why;
    if (!try_target(in, Viewpoint{p, std::atan2(dir.y(), dir.x()), n}, out, &why)) continue;
    for (size_t i = 0; i < set_aside_.size(); ++i) {
      if (pick[i] == kNo) continue;
      SetAsideEntry& e = set_aside_[i];
      ++e.retries, e.retry_pending = true;
      // Its flight's foot becomes a target again (to_flight_foot tries each foot once).
      if (pick[i] == kFlight)
        std::erase_if(flight_feet_tried_, [&](const Eigen::Vector3f& q) {
          return (q - e.p_m).head<2>().norm() < 3.0f;
        });
    }
    retrying_ = true;
    climbing_ = false;
    adopt_move(in, out, "retry: to a new vantage point for frontiers no path reached",
               /*committed=*/true);  // driven to its end, whatever it sees on the way
    return true;
  }
  return false;
}

// Stage 2's candidates for cluster c: its scored viewpoints (at most max_candidates_k), or, on a
// second visit or with none scored, its representative node facing the centroid.
std::vector<Viewpoint> LocalPlanner::viewpoints_of(const LocalPlanInput& in,
                                                   const Candidate& c) const {
  const graph::ReachableGraph& g = *in.graph;
  std::vector<Viewpoint> v;
  for (const auto& cv : *in.viewpoints) {
    if (cv.cluster_id != c.cluster_id) continue;
    for (const auto& gv : cv.viewpoints) {
      if (int(v.size()) >= plan_opt_.max_candidates_k) break;
      if (gv.node >= g.node_capacity() || !g.node(gv.node).alive) continue;
      if (!view_allowed(gv.p_m)) continue;
      v.push_back({gv.p_m.cast<double>(), double(gv.yaw_rad), gv.node});
    }
  }
  const bool approach =
      std::find(approached_.begin(), approached_.end(), c.cluster_id) != approached_.end();
  if (approach) v.clear();  // second visit: onto the frontier node itself
  if (v.empty()) {          // no scored viewpoint: stand on the representative, facing the centroid
    const auto& cl = (*in.clusters)[c.cluster_index];
    const Eigen::Vector3f p = g.node(c.rep).p_m;
    const Eigen::Vector3f d = cl.centroid_m - p;
    const double yaw = d.head<2>().norm() > 1e-3f ? std::atan2(d.y(), d.x()) : in.robot_yaw_rad;
    v.push_back({p.cast<double>(), yaw, c.rep});
  }
  return v;
}

// The robot's own level first: a cluster on another floor has no voxel path that the bounded A*
// finds, and trying its viewpoints spent each cycle's attempts (office seed 5, session 33: a
// ground-floor cluster 7 m below the robot, nearest in 3D, was tried every cycle; the upper
// corridor's cluster, reachable through the room's door, never was: "complete" at 58.8 %).
std::vector<size_t> off_graph_order(const std::vector<Eigen::Vector3f>& reps_m,
                                    const Eigen::Vector3f& robot_m, float band_m) {
  std::vector<size_t> idx(reps_m.size());
  for (size_t i = 0; i < idx.size(); ++i) idx[i] = i;
  auto other_level = [&](size_t i) { return std::abs(reps_m[i].z() - robot_m.z()) > band_m; };
  std::stable_sort(idx.begin(), idx.end(), [&](size_t a, size_t b) {
    const bool la = other_level(a), lb = other_level(b);
    if (la != lb) return lb;
    return (reps_m[a] - robot_m).squaredNorm() < (reps_m[b] - robot_m).squaredNorm();
  });
  return idx;
}

// PlanOptions::reach_off_graph. The last clusters have no path along G_real, but Stage 3 plans
// on the map (voxel A*): office seed 1 (session 26) ended "complete" in a room whose graph had no
// edge through its door, frontiers left in the corridor outside. They are tried on the map,
// the robot's level first, nearest first (off_graph_order); a cluster no trajectory reaches is set
// aside (it expires like any other, and path_retries retries it from elsewhere). The attempts of
// a cycle are bounded; the next cycle takes up the viewpoints after those tried, and until every
// one has been the search is not over (kSearching). Before, each cycle tried the same first 6 of
// a cluster's 8 viewpoints, the cluster was never set aside nor the 3 others tried, and the run
// ended "complete" with the upper floor at 87.3 % (office seed 3, guidance_near_m 4).
bool LocalPlanner::to_off_graph(const LocalPlanInput& in, std::vector<Candidate>& off,
                                LocalPlanResult& out) {
  if (!in.last_resort || !plan_opt_.reach_off_graph || off.empty() || !free_start(in)) {
    off_graph_tried_.clear();
    off_graph_cycles_ = 0;
    return false;
  }
  const graph::ReachableGraph& g = *in.graph;
  const Eigen::Vector3f robot = in.robot_foot_m.cast<float>();
  std::vector<Eigen::Vector3f> reps;
  for (const Candidate& c : off) reps.push_back(g.node(c.rep).p_m);
  const std::vector<size_t> order =
      off_graph_order(reps, robot, float(plan_opt_.floor_node_band_m));
  std::vector<Candidate> sorted;
  for (size_t i : order) sorted.push_back(off[i]);
  off.swap(sorted);
  // Progress of the clusters still off the graph; the others' entries are dropped.
  std::vector<OffGraphTried> progress;
  for (const Candidate& c : off) {
    const Eigen::Vector3f rep = g.node(c.rep).p_m;
    size_t tried = 0;
    for (const OffGraphTried& t : off_graph_tried_)
      if (t.cluster_id == c.cluster_id || (t.rep_m - rep).squaredNorm() < 0.25f)
        tried = std::max(tried, t.tried);
    progress.push_back({c.cluster_id, rep, tried});
  }
  off_graph_tried_.swap(progress);
  int attempts = 0;  // bounded work: the rest next cycle
  bool untried = false;
  for (size_t i = 0; i < off.size(); ++i) {
    const std::vector<Viewpoint> vps = viewpoints_of(in, off[i]);
    const graph::FrontierCluster& cluster = (*in.clusters)[off[i].cluster_index];
    SetAsideReason why = SetAsideReason::kAstarFailed;
    size_t& k = off_graph_tried_[i].tried;
    for (; k < vps.size() && attempts < opt_.max_stage3_attempts; ++k, ++attempts) {
      if (!try_target(in, vps[k], out, &why, Goal::kClusterView)) continue;
      adopt_target(in, cluster, out);
      out.replan_reason =
          "off the graph: no path along G_real to the last frontiers, one on the map";
      off_graph_tried_.clear();
      off_graph_cycles_ = 0;
      return true;
    }
    if (k >= vps.size())
      set_aside_cluster(in, cluster, why, last_hit_m_);  // every one tried
    else
      untried = true;
  }
  // Bounded: a cluster whose id and representative both change every cycle would start over.
  if (untried && off_graph_cycles_ < opt_.max_off_graph_cycles) {
    ++off_graph_cycles_;
    out.status = LocalPlanStatus::kSearching;
    out.replan_reason = "off the graph: viewpoints left to try on the map next cycle";
    return true;
  }
  off_graph_tried_.clear();
  off_graph_cycles_ = 0;
  return false;
}

void LocalPlanner::adopt_target(const LocalPlanInput& in, const graph::FrontierCluster& c,
                                LocalPlanResult& out) {
  // PlanOptions::replan_only_if_faster: a periodic replan to the same cluster whose trajectory
  // (from rest where the robot would stop, after braking there) arrives no earlier than the one
  // followed keeps the one followed. Each new trajectory starts at rest: one every replan_period_s
  // held the walk far below the speed limit (office seed 1: 0.56 m/s while walking, session 20).
  if (periodic_ && c.id == target_cluster_ && !current_.empty() && !out.trajectory.empty()) {
    const double brake_s = in.robot_velocity_mps.norm() / std::max(robot_.max_accel_mps2, 1e-3);
    const double left_s = current_.t_end() - on_trajectory_s(in);
    if (left_s <= brake_s + out.trajectory.duration() + kFasterMarginS) {
      has_target_ = true;
      remember_target(in, c);
      planned_at_s_ = in.t_s;
      keep_current(out, "periodic replan: the trajectory followed arrives as early");
      return;
    }
  }
  start_escapes_ = climbs_ = descents_ = 0;
  committed_ = false;
  has_target_ = true;
  remember_target(in, c);
  target_m_ = out.target_m;
  current_ = out.trajectory;
  planned_at_s_ = in.t_s;
  out.target_cluster = c.id;
  out.status = LocalPlanStatus::kNewTrajectory;
}

LocalPlanResult& LocalPlanner::keep_current(LocalPlanResult& out, const char* reason) const {
  out.status = LocalPlanStatus::kKeep;
  out.replan_reason = reason;
  out.trajectory = BsplineTrajectory{};
  out.path_m.clear();
  out.target_cluster = target_cluster_;
  out.target_m = target_m_;
  out.target_yaw_rad = 0;
  out.real_until_s = current_.t_end();
  return out;
}

double LocalPlanner::from_start_m(const Eigen::Vector3f& hit_m) const {
  return std::isnan(hit_m.x()) ? std::numeric_limits<double>::infinity()
                               : (hit_m.head<2>().cast<double>() - start_foot_m_.head<2>()).norm();
}

void LocalPlanner::adopt_move(const LocalPlanInput& in, LocalPlanResult& out, const char* reason,
                              bool committed) {
  has_target_ = true;
  committed_ = committed;
  target_cluster_ = -1;
  target_m_ = out.target_m;
  current_ = out.trajectory;
  planned_at_s_ = in.t_s;
  out.replan_reason = reason;
  out.status = LocalPlanStatus::kNewTrajectory;
}

// One entry per position: a node retried again keeps its latest (largest) count, so the list
// grows with the places retried, not with the retries.
void LocalPlanner::remember_retried(const SetAsideEntry& e) {
  for (Retried& q : retried_)
    if ((q.p_m - e.p_m).squaredNorm() < 1e-6f) {
      q.retries = std::max(q.retries, e.retries);
      return;
    }
  retried_.push_back({e.p_m, e.retries});
}

void LocalPlanner::release_retry() {
  size_t kept = 0;
  for (const SetAsideEntry& e : set_aside_) {
    if (!e.retry_pending) {
      set_aside_[kept++] = e;
      continue;
    }
    remember_retried(e);
    ++expired_total_;
  }
  set_aside_.resize(kept);
  retrying_ = false;
}

const graph::FrontierCluster* LocalPlanner::find_cluster(const LocalPlanInput& in,
                                                         int32_t id) const {
  for (const auto& c : *in.clusters)
    if (c.id == id) return &c;
  return nullptr;
}

void LocalPlanner::remember_target(const LocalPlanInput& in, const graph::FrontierCluster& c) {
  target_cluster_ = c.id;
  target_nodes_m_.clear();
  for (graph::NodeId n : c.nodes) target_nodes_m_.push_back(in.graph->node(n).p_m);
}

const graph::FrontierCluster* LocalPlanner::track_target(const LocalPlanInput& in) {
  if (const graph::FrontierCluster* c = find_cluster(in, target_cluster_)) {
    remember_target(in, *c);
    return c;
  }
  // Out of the guided subset only: still a frontier, still the target.
  if (plan_opt_.keep_guided_target && in.all_clusters && target_cluster_ >= 0)
    for (const auto& c : *in.all_clusters)
      if (c.id == target_cluster_) {
        remember_target(in, c);
        return &c;
      }
  if (target_cluster_ < 0) return nullptr;
  const graph::FrontierCluster* best = nullptr;
  float best_d = float(opt_.track_radius_m);
  for (const auto& c : *in.clusters)
    for (graph::NodeId n : c.nodes) {
      const Eigen::Vector3f p = in.graph->node(n).p_m;
      if (ignored(p)) continue;
      for (const Eigen::Vector3f& q : target_nodes_m_) {
        const float d = (p - q).head<2>().norm();
        if (d <= best_d && std::abs(p.z() - q.z()) < 0.5f) best_d = d, best = &c;
      }
    }
  if (!best) return nullptr;
  if (std::find(approached_.begin(), approached_.end(), target_cluster_) != approached_.end())
    approached_.push_back(best->id);
  remember_target(in, *best);
  return best;
}

void LocalPlanner::build_search_graph(const graph::ReachableGraph& g) {
  pos_scratch_.assign(g.node_capacity(), Eigen::Vector3d::Zero());
  for (size_t i = 0; i < g.node_capacity(); ++i)
    if (g.node(graph::NodeId(i)).alive)
      pos_scratch_[i] = g.node(graph::NodeId(i)).p_m.cast<double>();
  edges_scratch_.clear();
  for (size_t e = 0; e < g.edge_capacity(); ++e) {
    const graph::GraphEdge& ge = g.edge(graph::EdgeId(e));
    if (!ge.alive) continue;
    // Real elements only (confirmed and tentative are both G_real); hypothetical ones are the
    // macro layer's business.
    if (ge.state == graph::ElementState::kHypothetical) continue;
    edges_scratch_.push_back({ge.a, ge.b, double(std::max(ge.cost, ge.length_m))});
  }
  sg_ = SearchGraph::from_edges(pos_scratch_, edges_scratch_, /*undirected=*/true);
  sg_fresh_ = true;
}

graph::NodeId LocalPlanner::linked_node_near(const graph::ReachableGraph& g,
                                             const Eigen::Vector3f& p, float r, float dz) {
  near_scratch_.clear();
  g.nodes_within(p, r, dz, near_scratch_);
  graph::NodeId best_n = graph::kNoId;
  float best = std::numeric_limits<float>::infinity();
  for (graph::NodeId n : near_scratch_) {
    const float d = (g.node(n).p_m - p).squaredNorm();
    if (g.node(n).alive && g.node(n).degree > 0 && d < best) best = d, best_n = n;
  }
  return best_n;
}

void LocalPlanner::ensure_search_graph(const LocalPlanInput& in) {
  if (sg_fresh_) return;
  const graph::ReachableGraph& g = *in.graph;
  build_search_graph(g);
  const graph::NodeId root = g.root();
  robot_node_ = root != graph::kNoId && g.node(root).alive && g.node(root).degree > 0
                    ? root
                    : linked_node_near(g, in.robot_foot_m.cast<float>(), 1.5f, 1.0f);
}

// The body box with its margin may overlap an obstacle where the robot stands (tracking error,
// a door jamb seen late at close range): then every trajectory from there collides at its very
// first pose, and no target is ever reachable. The margin is what overlaps (the body itself is
// clear), so Stage 3 starts at the nearest collision-free pose within a few decimetres instead,
// which the control task reaches first (it tracks from the nearest point of a new trajectory).
bool LocalPlanner::free_start(const LocalPlanInput& in) {
  start_foot_m_ = in.robot_foot_m;
  start_yaw_ = in.robot_yaw_rad;
  start_velocity_.reset();
  BodyPose p{in.robot_foot_m, in.robot_yaw_rad, 0.0, in.t_s};
  const bool clear = !checker_.check_poses(*in.view, std::span<const BodyPose>(&p, 1)).collides;
  if (clear && plan_opt_.start_at_speed && in.robot_velocity_mps.allFinite() &&
      in.robot_velocity_mps.norm() > kAtSpeedMinMps)
    start_velocity_ = in.robot_velocity_mps;
  if (clear && plan_opt_.brake_start) brake_start(in);
  if (clear) return true;
  constexpr int kDirs = 16;
  constexpr double kYaws[] = {0.0, 0.3, -0.3, 0.6, -0.6, 1.2, -1.2, M_PI / 2, -M_PI / 2};
  double best = std::numeric_limits<double>::infinity();
  for (double d = 0.0; d <= opt_.escape_radius_m + 1e-9; d += 0.05)
    for (int a = 0; a < (d > 0 ? kDirs : 1); ++a)
      for (double dyaw : kYaws) {
        const double cost = d + 0.15 * std::abs(dyaw);
        if (cost >= best) continue;
        const double th = 2.0 * M_PI * a / kDirs;
        BodyPose q = p;
        q.foot_m += Eigen::Vector3d(d * std::cos(th), d * std::sin(th), 0.0);
        q.yaw_rad = in.robot_yaw_rad + dyaw;
        if (const auto s =
                in.view->support_surface_near(q.foot_m.cast<float>(), robot_.step_height_m))
          q.foot_m.z() = s->height_m;
        if (checker_.check_poses(*in.view, std::span<const BodyPose>(&q, 1)).collides) continue;
        best = cost;
        start_foot_m_ = q.foot_m;
        start_yaw_ = q.yaw_rad;
      }
  return std::isfinite(best);
}

// PlanOptions::brake_start: where a moving robot comes to rest, braking at the acceleration limit
// (|v|^2 / (2 a_max) on): along the trajectory it follows (the control task brakes on it before
// it enters a new one), else straight along its velocity. Taken as the start where the body is
// clear every 0.05 m on the way (on the trajectory: its own poses; straight: the robot's yaw and
// 0.6 rad either side), over no untraversable support.
void LocalPlanner::brake_start(const LocalPlanInput& in) {
  const Eigen::Vector2d v = in.robot_velocity_mps;
  const RestOnTrajectory on =
      rest_on_trajectory(checker_, *in.view, robot_, current_, in.robot_foot_m, v,
                         on_trajectory_s(in), in.t_s, plan_opt_.brake_along_motion);
  if (on.kind == RestOnTrajectory::Kind::kBlocked) return;
  if (on.kind == RestOnTrajectory::Kind::kRest) {
    start_foot_m_ = on.pose.foot_m;
    start_yaw_ = on.pose.yaw_rad;
    return;
  }
  if (const auto rest = straight_rest_point(checker_, *in.view, robot_, in.robot_foot_m,
                                            in.robot_yaw_rad, v, in.t_s))
    start_foot_m_ = *rest;
}

bool LocalPlanner::no_progress(const LocalPlanInput& in) {
  if (!progress_.stalled(in.robot_foot_m, in.robot_yaw_rad, in.t_s, has_target_,
                         plan_opt_.no_progress_s))
    return false;
  ++no_progress_events_;
  return true;
}

bool LocalPlanner::floor_stale(const LocalPlanInput& in) {
  const size_t nodes = in.graph->node_count();
  if (nodes >= growth_mark_nodes_ + size_t(std::max(opt_.stale_floor_nodes, 0)) ||
      in.t_s < growth_mark_t_s_) {
    growth_mark_nodes_ = std::max(nodes, growth_mark_nodes_);
    growth_mark_t_s_ = in.t_s;
  }
  return plan_opt_.stale_floor_s > 0 && in.t_s - growth_mark_t_s_ >= plan_opt_.stale_floor_s;
}

// A straight step to the nearest pose where the body can turn (escape.hpp), from the Stage 3
// start; with away_from, one that gains distance from that point.
bool LocalPlanner::escape(const LocalPlanInput& in, LocalPlanResult& out,
                          const Eigen::Vector3f* away_from) {
  if (!away_from && can_turn_at(checker_, *in.view, start_foot_m_, start_yaw_)) return false;
  auto w = escape_to_turn(checker_, *in.view, robot_, start_foot_m_, start_yaw_, in.t_s,
                          opt_.escape_turn_radius_m, away_from);
  if (!w) return false;
  take_walk(std::move(*w), start_yaw_, out);
  return true;
}

bool LocalPlanner::to_foot_of(const LocalPlanInput& in, const FlightFoot& f, LocalPlanResult& out) {
  const double step = robot_.step_height_m;
  ensure_search_graph(in);
  for (double extra = 0.0; extra <= 0.75 + 1e-9; extra += 0.25) {
    const Eigen::Vector2d p = f.foot_m.head<2>() - extra * f.axis.dir;
    const auto sp = in.view->support_surface_near(
        Eigen::Vector3f(float(p.x()), float(p.y()), float(f.foot_m.z())), 0.5 * step);
    if (!sp || !sp->reachable) continue;
    const Eigen::Vector3f q(float(p.x()), float(p.y()), sp->height_m);
    // The nearest linked node: the walk along G_real where the voxel A* finds no path (a sparse
    // map, or a trip across the building past its expansion limit).
    const graph::NodeId n = linked_node_near(*in.graph, q, 0.75f, 0.3f);
    SetAsideReason why = SetAsideReason::kAstarFailed;
    if (try_target(in, Viewpoint{q.cast<double>(), f.yaw_rad, n}, out, &why, Goal::kFlightFoot))
      return true;
  }
  return false;
}

bool LocalPlanner::to_flight_foot(const LocalPlanInput& in, const graph::FrontierCluster& c,
                                  LocalPlanResult& out) {
  if (!plan_opt_.climb_blind || !plan_opt_.flight_foot) return false;
  std::vector<Eigen::Vector3d> near;
  for (graph::NodeId n : c.nodes) near.push_back(in.graph->node(n).p_m.cast<double>());
  const auto f = flight_foot(*in.view, near, in.robot_foot_m.z());
  if (!f) return false;
  remember_flight(*f);
  const Eigen::Vector3f foot = f->foot_m.cast<float>();
  for (const Eigen::Vector3f& q : flight_feet_tried_)
    if ((q - foot).norm() < 0.3f) return false;
  flight_feet_tried_.push_back(foot);
  flight_foot_ = *f;
  if (!free_start(in) || !to_foot_of(in, *f, out)) return false;
  adopt_target(in, c, out);
  flight_target_ = true;
  out.replan_reason = "to a flight's foot: a frontier beside it, on the axis where a climb starts";
  return true;
}

bool LocalPlanner::to_flight_lead(const LocalPlanInput& in, LocalPlanResult& out, bool stale) {
  if (!plan_opt_.climb_blind || !plan_opt_.flight_foot) return false;
  const char* const reason =
      stale ? "to a flight's foot: the floor's graph stopped growing, the flight rises out of reach"
            : "to a flight's foot: the floor is done, the flight rises out of reach";
  const graph::ReachableGraph& g = *in.graph;
  const Eigen::Vector3f robot = in.robot_foot_m.cast<float>();
  // A trip to a lead's foot cut short (frontiers came back on the way, teaching_building seed 1:
  // the foot was never reached and, tried once, never again): taken up again, a few times.
  if (lead_trip_ && (lead_trip_->foot.foot_m - in.robot_foot_m).head<2>().norm() > 0.5 &&
      lead_trip_->trips < kMaxLeadTrips) {
    ++lead_trip_->trips;
    flight_foot_ = lead_trip_->foot;
    if (free_start(in) && to_foot_of(in, flight_foot_, out)) {
      adopt_foot(in, flight_foot_, reason, out);
      return true;
    }
  }
  lead_trip_.reset();
  std::vector<std::pair<float, graph::NodeId>> leads;
  for (graph::NodeId i = 0; i < g.node_capacity(); ++i) {
    const graph::GraphNode& n = g.node(i);
    if (!n.alive || !n.flight_lead ||
        std::abs(n.p_m.z() - robot.z()) >= float(plan_opt_.floor_node_band_m) || ignored(n.p_m))
      continue;
    // Each lead is looked at once (flight_foot scans the map around it): most are no flight
    // (teaching_building seed 1: 23 leads, one at its stairs).
    const bool tried =
        std::any_of(leads_tried_.begin(), leads_tried_.end(),
                    [&](const Eigen::Vector3f& q) { return (q - n.p_m).norm() < 0.3f; });
    if (!tried) leads.emplace_back((n.p_m - robot).head<2>().norm(), i);
  }
  std::sort(leads.begin(), leads.end());
  for (const auto& [d, i] : leads) {
    leads_tried_.push_back(g.node(i).p_m);
    graph::FrontierCluster c;
    c.nodes = {i};
    c.centroid_m = g.node(i).p_m;
    if (to_flight_foot(in, c, out)) {
      lead_trip_ = LeadTrip{flight_foot_, 1};
      out.replan_reason = reason;
      return true;
    }
  }
  return false;
}

void LocalPlanner::remember_flight(const FlightFoot& f) {
  for (const FoundFlight& k : flights_found_)
    if ((k.foot.foot_m - f.foot_m).norm() < 0.5) return;
  flights_found_.push_back({f});
}

// No target left on this floor, but a flight found on it never led up (the robot stood on it and
// came back down, or never climbed it): its foot, and from there the climb, before the verdict
// (teaching_building seed 4, session 39: two descents from the first flight early on, "complete"
// at 1034 s with the floor above never explored). A few trips per flight.
bool LocalPlanner::to_found_flight(const LocalPlanInput& in, LocalPlanResult& out) {
  if (!plan_opt_.climb_blind || !plan_opt_.flight_foot) return false;
  std::vector<std::pair<double, size_t>> order;
  for (size_t i = 0; i < flights_found_.size(); ++i) {
    const FoundFlight& k = flights_found_[i];
    if (k.led_up || k.trips >= kMaxFoundFlightTrips ||
        std::abs(k.foot.foot_m.z() - in.robot_foot_m.z()) > plan_opt_.floor_node_band_m)
      continue;
    order.emplace_back((k.foot.foot_m - in.robot_foot_m).head<2>().norm(), i);
  }
  if (order.empty() || !free_start(in)) return false;  // (its collision check only when needed)
  std::sort(order.begin(), order.end());
  for (const auto& [d, i] : order) {
    FoundFlight& k = flights_found_[i];
    ++k.trips;
    if (!to_foot_of(in, k.foot, out)) continue;
    adopt_foot(in, k.foot, "to a flight's foot: no target left, a flight found here never led up",
               out);
    return true;
  }
  return false;
}

bool LocalPlanner::to_next_flight(const LocalPlanInput& in, LocalPlanResult& out) {
  if (!plan_opt_.climb_blind || !plan_opt_.flight_foot) return false;
  const auto f = flight_foot(*in.view, {in.robot_foot_m}, in.robot_foot_m.z(), 0.45, 2.0, 1.0,
                             /*sparse=*/true);
  if (!f) return false;
  remember_flight(*f);
  const char* reason = "to a flight's foot: from the landing, the next flight up";
  // No path on the map: the landing, reached blind, is not in it under the robot (no start
  // support for the voxel search, no graph node; teaching_building seed 3, session 39, for 15 s).
  // Across the landing at its height, facing up the next flight, if the body fits on the map.
  const auto across = [&]() {
    if (std::abs(f->foot_m.z() - in.robot_foot_m.z()) > 0.5 * robot_.step_height_m) return false;
    const Eigen::Vector3d to(f->foot_m.x(), f->foot_m.y(), in.robot_foot_m.z());
    if ((to - in.robot_foot_m).head<2>().norm() < 0.1 ||
        !straight_walk(in, {in.robot_foot_m, to}, f->yaw_rad, out))
      return false;
    reason = "to a flight's foot: from the landing, across it to the next flight up";
    return true;
  };
  if (!free_start(in) || !(to_foot_of(in, *f, out) || across())) {
    if (next_flight_wait_until_s_ < 0) next_flight_wait_until_s_ = in.t_s + opt_.climb_settle_s;
    return false;
  }
  next_flight_wait_until_s_ = -1;
  adopt_foot(in, *f, reason, out);
  next_flight_ = true;
  return true;
}

void LocalPlanner::adopt_foot(const LocalPlanInput& in, const FlightFoot& f, const char* reason,
                              LocalPlanResult& out) {
  flight_foot_ = f;
  graph::FrontierCluster c;  // no frontier: the foot itself is the target
  c.centroid_m = f.foot_m.cast<float>();
  adopt_target(in, c, out);
  flight_target_ = true;
  out.replan_reason = reason;
}

bool LocalPlanner::straight_walk(const LocalPlanInput& in, const std::vector<Eigen::Vector3d>& pts,
                                 double yaw, LocalPlanResult& out) {
  auto w = plan::straight_walk(checker_, *in.view, robot_, pts, yaw, in.t_s,
                               plan_opt_.turn_before_walk ? in.robot_yaw_rad : NAN);
  if (!w) return false;
  take_walk(std::move(*w), yaw, out);
  return true;
}

void LocalPlanner::take_walk(StraightWalk&& w, double yaw, LocalPlanResult& out) {
  out.trajectory = std::move(w.trajectory);
  out.path_m = {w.from_m, w.to_m};
  out.target_m = w.to_m;
  out.target_yaw_rad = yaw;
  out.real_until_s = out.trajectory.t_end();
}

namespace {

// The flight rising (sign +1) or falling (-1) ahead of a robot at `foot` facing `face` (unit),
// looked for from `ahead` m along `face` on level ground of the same floor (flight_axis wants the
// treads 0.6 and 0.9 m ahead of where it starts).
std::optional<FlightAxis> axis_facing(const map::MapView& view, const Eigen::Vector3d& foot,
                                      const Eigen::Vector2d& face, double ahead, double step_m,
                                      double sign) {
  Eigen::Vector3d from = foot;
  from.head<2>() += ahead * face;
  if (ahead > 0) {
    const auto sp = view.support_surface_near(from.cast<float>(), 0.5 * step_m);
    if (!sp || sp->state != map::TravState::kTraversable) return std::nullopt;
    from.z() = sp->height_m;
  }
  return flight_axis(view, from, face, sign);
}

// The body moves over the nosings, not down into each tread: each point no lower than a support
// point of `sup` within 0.2 m toward the flight's higher end (`up`, unit; a stepwise profile,
// smoothed by the B-spline, dips the body into the risers).
void keep_over_nosings(std::vector<Eigen::Vector3d>& pts, const std::vector<Eigen::Vector3d>& sup,
                       const Eigen::Vector2d& up) {
  for (Eigen::Vector3d& p : pts)
    for (const Eigen::Vector3d& q : sup) {
      const double ds = (q.head<2>() - p.head<2>()).dot(up);
      if (ds > 0 && ds <= 0.2 + 1e-6) p.z() = std::max(p.z(), q.z());
    }
}

}  // namespace

// On a flight the body pitches with the stairs and the LiDAR's +-15 deg look over the treads
// ahead: the rest of the flight and its landing are never seen from on it, and a frontier there
// stays one however long the robot stands on it. Facing up a flight (its axis from the map's
// risers, flight_axis), walk straight up the axis to the last support seen and landing_step_m
// beyond it: the legs find the landing (the firmware enters the ground under the feet as support
// when the map has none there) and the LiDAR, level again, sees the floor. The blind part is
// allowed only where rays crossed the body's space (no wall unseen) and nothing observed lies
// more than a step below the last support (no known drop).
bool LocalPlanner::climb_on(const LocalPlanInput& in, LocalPlanResult& out, bool on_flight_only,
                            const FlightFoot* given, bool stored_axis) {
  const map::MapView& view = *in.view;
  const Eigen::Vector3d foot = in.robot_foot_m;
  // The flight the robot faces; at a frontier at a flight's foot (not yet on it) also one beside
  // or behind it (the walk turns onto the axis), found from the foot or, at a frontier, from up to
  // PlanOptions::climb_axis_ahead_m ahead on level ground. At a flight's foot (to_flight_foot) the
  // axis found from there.
  std::optional<FlightAxis> axis;
  // With flight_foot, at a partial climb's end on the top tread: that climb's axis (no flight
  // rises ahead any more; the landing ahead is what is left).
  const ClimbedFlight* end_of =
      plan_opt_.flight_foot && on_flight_only ? partial_climb_end(foot) : nullptr;
  if (given) axis = given->axis;
  if (end_of && stored_axis) axis = end_of->axis;
  for (double ahead = 0.0;
       ahead <= (on_flight_only ? 0.0 : plan_opt_.climb_axis_ahead_m) + 1e-9 && !axis; ahead += 0.3)
    for (int k = 0; k < (on_flight_only ? 1 : 4) && !axis; ++k) {
      const double yaw = in.robot_yaw_rad + k * M_PI / 2;
      const Eigen::Vector2d face(std::cos(yaw), std::sin(yaw));
      axis = axis_facing(view, foot, face, ahead, robot_.step_height_m, 1.0);
      if (axis && axis->dir.dot(face) < std::cos(M_PI / 4)) axis.reset();
    }
  if (!axis) return false;
  const double vs = view.voxel_size_m(), step = robot_.step_height_m;
  const Eigen::Vector2d o =
      axis->origin + axis->dir * (foot.head<2>() - axis->origin).dot(axis->dir);
  // On the flight: a blind climb's path below its landing (the treads walked over blind are not
  // in the map), or a tread 0.3-0.6 m back, one or two treads lower (half a metre back alone was
  // two treads down at some places on the house's flight, and the robot stood there unclimbed).
  if (on_flight_only && !below_climbed_landing(foot)) {
    bool lower = false;
    for (double d = 0.3; d <= 0.6 + 1e-9 && !lower; d += 0.15) {
      const Eigen::Vector2d b = o - d * axis->dir;
      const auto sb = view.support_surface_near(
          Eigen::Vector3f(float(b.x()), float(b.y()), float(foot.z() - step)), step + 0.05);
      lower = sb && sb->height_m <= foot.z() - 0.5 * step;
    }
    if (!lower) return false;
  }
  // Up the axis over the support the map holds; unseen treads (edge-on) are bridged up to 0.45 m.
  std::vector<Eigen::Vector3d> pts{foot};
  double z = foot.z(), s_last = 0, gap = 0;
  // From a flight's foot: the floor up to the first riser is walked level (often unseen: the
  // LiDAR's blind ring where the robot stood to see the flight), and a tread unseen across the
  // line leaves the next one two steps up: past a gap, support up to a 40 deg grade is taken.
  // With flight_foot the same on the flight (a tread below checked above): pitched up, the LiDAR
  // looks over the next treads (house seed 6: a climb stopped mid-flight by the look-ahead found
  // nothing ahead within a step and the robot stood there until "complete").
  const double s_riser = given ? (given->riser_m.head<2>() - o).dot(axis->dir)
                               : -std::numeric_limits<double>::infinity();
  for (double s = vs; s <= 8.0 && gap <= 0.45; s += vs) {
    const Eigen::Vector2d q = o + s * axis->dir;
    if (s < s_riser - 0.5 * vs) {
      pts.emplace_back(q.x(), q.y(), foot.z());
      continue;
    }
    const double rise =
        given || (on_flight_only && plan_opt_.flight_foot) ? step + 0.84 * gap : step;
    const auto sp = view.support_surface_near(
        Eigen::Vector3f(float(q.x()), float(q.y()), float(z + 0.5 * rise)), 0.5 * rise + 0.03);
    if (sp && sp->height_m >= z - 0.03) {
      z = sp->height_m, s_last = s, gap = 0;
      pts.emplace_back(q.x(), q.y(), z);
    } else {
      gap += vs;
    }
  }
  const bool climb_end = end_of != nullptr;  // the landing ahead is what is left
  if (!climb_end && z - foot.z() < 0.5 * step && s_last < 0.3) return false;  // nothing to climb
  // Stairs only: on a ramp the body pitches less than the LiDAR's half field of view and the
  // ground ahead stays in sight. A flight shows its nosings as step edges (from its foot, where
  // few are marked, flight_foot found its treads a step apart). With flight_foot, on the flight
  // the lower tread behind counts for two: near the top few nosings ahead are marked (office
  // seed 4: 1.3 m below the landing, one step edge; every Stage 3 trajectory from there hit the
  // stairwell and each frontier was set aside in turn until "complete").
  int edges = given || climb_end ? 3 : plan_opt_.flight_foot && on_flight_only ? 2 : 0;
  for (const Eigen::Vector3d& p : pts)
    edges += view.is_step_edge(
        view.key_of(Eigen::Vector3f(float(p.x()), float(p.y()), float(p.z() - 0.01))));
  if (edges < 3) return false;
  // Onto the landing, blind: rays crossed the body's space there, no drop observed below. A
  // wall seen on it ends the landing there (test_stair's ends 0.8 m past the top tread: a climb
  // planned before that wall was seen ran into it and was dropped mid-flight). At a partial
  // climb's end rays up to look_above_m over the body count too: on the top tread the body
  // pitches up with the flight and every ray passes over the landing's body space (office seed 1:
  // the landing, 1.25 m deep to its wall, never seen at body height; no node grew there). Not
  // from below: rays pass over the treads of a flight too (test_stair: "landings" mid-flight).
  const double body_lo = z + step, body_hi = z + robot_.body_height_m;
  const double look_above_m = climb_end ? 0.6 : 0.0;
  const size_t n_flight = pts.size();
  bool unseen = false;
  for (double s = s_last + vs; s <= s_last + opt_.landing_step_m + 1e-9; s += vs) {
    const Eigen::Vector2d q = o + s * axis->dir;
    bool seen = false, wall = false;
    for (double h = body_lo; h <= body_hi + look_above_m && !wall; h += vs) {
      const map::Occupancy oc =
          view.occupancy(Eigen::Vector3f(float(q.x()), float(q.y()), float(h)));
      wall = oc == map::Occupancy::kOccupied && h <= body_hi;
      seen |= oc == map::Occupancy::kFree;
    }
    if (wall) break;
    if (!seen) {
      unseen = true;
      break;
    }
    bool drop = false;
    for (double h = z - step - vs; h >= z - 1.0 && !drop; h -= vs)
      drop = view.occupancy(Eigen::Vector3f(float(q.x()), float(q.y()), float(h))) ==
             map::Occupancy::kOccupied;
    if (drop) {
      // Right past the last support, from a flight's foot or on the flight: the floor under an
      // open flight shows through its risers where the next treads are not seen yet. A partial
      // climb to the last support, then on from there (teaching_building seed 1, session 22: the
      // floor 0.38 m below the third tread ended every climb from the foot).
      if ((given || on_flight_only) && pts.size() == n_flight) {
        unseen = true;
        break;
      }
      return false;
    }
    pts.emplace_back(q.x(), q.y(), z);
  }
  // The body moves over the nosings: heights no lower than the line from the robot to the last
  // support, nor than the next tread within 0.2 m ahead.
  const double s_top = std::max(s_last, vs);
  const std::vector<Eigen::Vector3d> sup = pts;
  for (Eigen::Vector3d& p : pts) {
    const double s = std::clamp((p.head<2>() - o).dot(axis->dir), 0.0, s_top);
    p.z() = std::max(p.z(), foot.z() + (z - foot.z()) * s / s_top);
  }
  keep_over_nosings(pts, sup, axis->dir);
  // Nothing seen past the last support (the treads above it unseen yet): a partial climb up to
  // it, at least two steps up; climbing goes on from there (below_climbed_landing).
  climb_partial_ = unseen && pts.size() == n_flight;
  climb_axis_ = FlightAxis{o, axis->dir, axis->width_m};
  const double yaw = std::atan2(axis->dir.y(), axis->dir.x());
  if (climb_partial_) {
    if (z - foot.z() < 2 * step - 0.03) return false;  // (two treads: 0.34 m, 0.337 in the map)
    return straight_walk(in, pts, yaw, out);
  }
  // The longest walk the body fits (its front stops short of a wall), ending at least
  // min_landing_m past where the flight reached the landing's height.
  double s_reach = s_top;
  for (const Eigen::Vector3d& p : sup)
    if (p.z() >= z - 0.03) {
      s_reach = (p.head<2>() - o).dot(axis->dir);
      break;
    }
  for (int tries = 0;
       tries < 16 && pts.size() > 1 &&
       (pts.back().head<2>() - o).dot(axis->dir) >= s_reach + opt_.min_landing_m - 1e-6;
       ++tries, pts.pop_back())
    if (straight_walk(in, pts, yaw, out)) return true;
  return false;
}

const LocalPlanner::ClimbedFlight* LocalPlanner::partial_climb_end(
    const Eigen::Vector3d& foot) const {
  for (const ClimbedFlight& f : climbed_)
    if (f.partial && (f.end_m.cast<double>() - foot).head<2>().norm() < 0.5 &&
        std::abs(foot.z() - f.end_m.z()) < robot_.step_height_m)
      return &f;
  return nullptr;
}

// On a flight in a stairwell a B-spline's curve swings the body into the side walls: every Stage 3
// trajectory from there hits them next to the start, and without this each frontier was set
// aside in turn until "complete" (office seed 4: on the way down, floor 0 left at 80.9 %). The
// flight's treads below are in the map (the robot came up them, and the LiDAR looks down them):
// walk straight down its axis over that support, at a constant yaw along the axis (backwards if
// the robot faces up), to 0.5 m of level floor past its foot (from a landing, first level to
// the top riser).
bool LocalPlanner::descend_flight(const LocalPlanInput& in, LocalPlanResult& out) {
  const map::MapView& view = *in.view;
  const Eigen::Vector3d foot = in.robot_foot_m;
  const double vs = view.voxel_size_m(), step = robot_.step_height_m;
  // From the robot, or from up to 0.6 m ahead on level ground (flight_axis wants the drop 0.6
  // and 0.9 m ahead; on a landing the robot stands farther back from the top riser).
  for (int k = 0; k < 8; ++k) {
    const double yaw0 = in.robot_yaw_rad + (k % 4) * M_PI / 2, ahead = k < 4 ? 0.0 : 0.6;
    const Eigen::Vector2d face(std::cos(yaw0), std::sin(yaw0));
    const auto axis = axis_facing(view, foot, face, ahead, step, -1.0);
    if (!axis) continue;
    const Eigen::Vector2d o =
        axis->origin + axis->dir * (foot.head<2>() - axis->origin).dot(axis->dir);
    std::vector<Eigen::Vector3d> pts{foot};
    double z = foot.z(), level = 0, gap = 0;
    bool down = false;  // level is counted only past the first drop
    for (double s = vs; s <= 8.0 && (!down || level < 0.5) && gap <= 0.45; s += vs) {
      const Eigen::Vector2d q = o + s * axis->dir;
      const double drop = step + 0.84 * gap;  // past an unseen tread, down to a 40 deg grade
      const auto sp = view.support_surface_near(
          Eigen::Vector3f(float(q.x()), float(q.y()), float(z - 0.5 * drop)), 0.5 * drop + 0.03);
      if (!sp || sp->height_m > z + 0.03) {  // unseen, or rising
        gap += vs;
        continue;
      }
      down |= sp->height_m < z - 0.03;
      level = sp->height_m < z - 0.03 ? 0.0 : level + vs;
      z = std::min<double>(z, sp->height_m), gap = 0;
      pts.emplace_back(q.x(), q.y(), z);
    }
    if (foot.z() - z < 2 * step || level < 0.3) continue;  // not to a floor two steps down
    keep_over_nosings(pts, std::vector<Eigen::Vector3d>(pts), -axis->dir);
    double yaw = std::atan2(axis->dir.y(), axis->dir.x());
    if (std::cos(yaw - in.robot_yaw_rad) < 0) yaw += M_PI;  // facing up: backwards down
    if (straight_walk(in, pts, std::remainder(yaw, 2.0 * M_PI), out)) return true;
  }
  return false;
}

bool LocalPlanner::below_climbed_landing(const Eigen::Vector3d& foot) const {
  if (partial_climb_end(foot)) return true;
  for (const ClimbedFlight& f : climbed_) {
    if (foot.z() > f.top_z_m - robot_.step_height_m) continue;
    for (const Eigen::Vector3f& q : f.path_m)
      if ((q.cast<double>() - foot).head<2>().norm() < 0.5) return true;
  }
  return false;
}

bool LocalPlanner::on_climbed_flight(const Eigen::Vector3f& p) const {
  for (const ClimbedFlight& f : climbed_) {
    if (p.z() > f.top_z_m + 0.1f) continue;
    for (const Eigen::Vector3f& q : f.path_m)
      if ((q - p).head<2>().norm() < 0.8f) return true;
  }
  return false;
}

bool LocalPlanner::on_deferred_flight(const Eigen::Vector3f& p) const {
  if (!deferred_climb_) return false;
  const DeferredClimb& d = *deferred_climb_;
  const Eigen::Vector3f a = d.foot_m.cast<float>(), b = d.end_m.cast<float>();
  const float step = float(robot_.step_height_m);
  const Eigen::Vector2f ab = (b - a).head<2>();
  const float len = ab.norm();
  if (len < 0.3f || p.z() < a.z() + 0.5f * step) return false;
  const Eigen::Vector2f dir = ab / len, ap = (p - a).head<2>();
  // A partial climb ended at the last tread seen: the flight goes on, no steeper than 45 deg (3 m
  // more covers a storey's flight); a whole one ended on its landing.
  const float s = ap.dot(dir), off = std::abs(ap.x() * dir.y() - ap.y() * dir.x());
  if (s < 0.f || s > len + (d.partial ? 3.f : 0.f) || off > 0.8f) return false;
  return p.z() <= b.z() + std::max(s - len, 0.f) + step;
}

int LocalPlanner::other_targets(const LocalPlanInput& in, int32_t except_id) const {
  const graph::ReachableGraph& g = *in.graph;
  int n_other = 0;
  for (const graph::FrontierCluster& c : *in.clusters) {
    if (c.id == except_id) continue;
    n_other += std::any_of(c.nodes.begin(), c.nodes.end(),
                           [&](graph::NodeId n) { return !ignored(g.node(n).p_m); });
  }
  return n_other;
}

bool LocalPlanner::try_target(const LocalPlanInput& in, const Viewpoint& vp, LocalPlanResult& out,
                              SetAsideReason* why, Goal goal) {
  *why = SetAsideReason::kAstarFailed;
  last_hit_m_ = kNoHitM;
  ++out.astar_calls;
  VoxelPath path = astar_.plan(*in.view, start_foot_m_, vp.p_m);
  // The ground under the feet may be in the LiDAR's blind ring (start-up): search from the
  // nearest confirmed graph nodes instead, the closest observed support the robot stands by.
  for (size_t k = 0; path.status == VoxelAStarStatus::kNoStartSupport && k < start_nodes_m_.size();
       ++k) {
    path = astar_.plan(*in.view, start_nodes_m_[k], vp.p_m);
    if (path.status == VoxelAStarStatus::kOk)
      path.points_m.insert(path.points_m.begin(), start_foot_m_);
  }
  // The path along G_real: its edges were checked over the support surface by the graph
  // (tentative ones may bridge short under-observed gaps, max_gap_m), with the body's half width
  // beside them: what a sparse standstill VLP-16 map (rings of ground 0.3-0.4 m apart) still
  // supports, and a second opinion where the voxel A* path hugs a door jamb.
  auto graph_path = [&]() {
    if (vp.node >= sg_.num_nodes() || robot_node_ >= sg_.num_nodes()) return false;
    const PathResult gp = pair_search_.astar(sg_, robot_node_, vp.node);
    if (!gp.found) return false;
    path.points_m.clear();
    path.points_m.push_back(start_foot_m_);
    for (uint32_t u : gp.nodes) path.points_m.push_back(sg_.position(u));
    // A viewpoint beside its node (a flight's foot, to_foot_of): on to it.
    if (path.points_m.size() == 2 || (path.points_m.back() - vp.p_m).norm() > 0.05)
      path.points_m.push_back(vp.p_m);
    path.status = VoxelAStarStatus::kOk;
    ++out.graph_fallbacks;
    return true;
  };
  bool on_graph = false;
  if (path.status != VoxelAStarStatus::kOk) on_graph = graph_path();
  if (path.status != VoxelAStarStatus::kOk || path.points_m.empty()) return false;
  *why = SetAsideReason::kTrajectoryFailed;
  // The path starts at the robot's support voxel; start the curve at the robot itself (or at
  // the nearest collision-free pose, see free_start()). The B-spline is checked against the
  // body with FCL whichever path it follows.
  path.points_m.front() = start_foot_m_;
  // A flight's foot: onto its axis from where the search stopped (within astar_goal_tolerance_m;
  // house seed 5 with a 0.3 rad yaw gate stood 0.21 m beside the axis, the climb from there failed
  // and the flight was never tried again), no nearer the first riser than the search came (the
  // body's front over the riser pitches it). Without that step if the body meets something.
  std::vector<Eigen::Vector3d> short_of_foot;
  if (goal == Goal::kFlightFoot) {
    const Eigen::Vector2d axis(std::cos(vp.yaw_rad), std::sin(vp.yaw_rad));
    const Eigen::Vector2d off = (path.points_m.back() - vp.p_m).head<2>();
    if (std::abs(off.x() * axis.y() - off.y() * axis.x()) > 0.05) {
      short_of_foot = path.points_m;
      Eigen::Vector3d on_axis = vp.p_m;
      on_axis.head<2>() += std::min(0.0, off.dot(axis)) * axis;
      path.points_m.push_back(on_axis);
    }
  }
  const bool to_foot = !short_of_foot.empty();
  // The goal yaw: the viewpoint's (facing the cluster), none with PlanOptions::face_cluster off
  // for a cluster's viewpoint (the curve's own end yaw), a flight's axis if the path ends on one.
  const bool free_yaw = goal == Goal::kClusterView && !plan_opt_.face_cluster;
  auto goal_of = [&]() -> std::optional<double> {
    const double y = shape_path(*in.view, path.points_m,
                                free_yaw ? std::numeric_limits<double>::quiet_NaN() : vp.yaw_rad);
    return std::isfinite(y) ? std::optional<double>(y) : std::nullopt;
  };
  std::optional<double> goal_yaw = goal_of();
  // PlanOptions::start_at_speed: the same path from the robot's foot (before the braking start,
  // if one was taken), leaving along its velocity; from rest where that curve is not clear or
  // must slow below kAtSpeedShare of the speed at once (a bend at its very start).
  auto build = [&](std::optional<double> yaw) {
    if (start_velocity_) {
      std::vector<Eigen::Vector3d> from_robot;
      if ((path.points_m.front() - in.robot_foot_m).head<2>().norm() > 0.01)
        from_robot.push_back(in.robot_foot_m);
      from_robot.insert(from_robot.end(), path.points_m.begin(), path.points_m.end());
      TrajectoryResult t = builder_.build(*in.view, checker_, from_robot, in.robot_yaw_rad, yaw,
                                          in.t_s, *start_velocity_);
      if (t.status == TrajectoryStatus::kOk &&
          t.start_speed_mps >= kAtSpeedShare * start_velocity_->norm())
        return t;
    }
    return builder_.build(*in.view, checker_, path.points_m, start_yaw_, yaw, in.t_s);
  };
  TrajectoryResult tr = build(goal_yaw);
  auto failed = [&]() {
    if (tr.hit.collides) last_hit_m_ = tr.hit.voxel_m.cast<float>();
    return tr.status != TrajectoryStatus::kOk && tr.status != TrajectoryStatus::kPolyline;
  };
  // PlanOptions::arrive_along_path: the body hit something within a body length of the
  // viewpoint, turning to its heading: arrive facing along the path (the curve's own end yaw).
  auto along_path = [&]() {
    if (!plan_opt_.arrive_along_path || !goal_yaw || !tr.hit.collides ||
        (tr.hit.voxel_m - vp.p_m).head<2>().norm() > robot_.body_length_m)
      return false;
    tr = build(std::nullopt);
    if (failed()) return false;
    goal_yaw = tr.trajectory.pose(tr.trajectory.t_end()).yaw_rad;
    return true;
  };
  if (to_foot && failed()) {
    path.points_m = std::move(short_of_foot);
    goal_yaw = goal_of();
    tr = build(goal_yaw);
  }
  if (failed() && !along_path()) {
    if (on_graph || !graph_path()) return false;
    goal_yaw = goal_of();
    tr = build(goal_yaw);
    if (failed() && !along_path()) return false;
  }
  out.trajectory = std::move(tr.trajectory);
  out.path_m = std::move(path.points_m);
  out.target_m = vp.p_m;
  out.target_yaw_rad = goal_yaw ? *goal_yaw : out.trajectory.pose(out.trajectory.t_end()).yaw_rad;
  out.real_until_s = out.trajectory.t_end();  // the local layer plans on G_real only
  return true;
}

LocalPlanResult LocalPlanner::plan(const LocalPlanInput& in) {
  LocalPlanResult out;
  periodic_ = false;
  sg_fresh_ = false;  // the graph may have changed since the last cycle
  if (!in.view || !in.graph || !in.clusters || !in.viewpoints || !in.robot_foot_m.allFinite()) {
    out.status = LocalPlanStatus::kBadInput;
    return out;
  }
  const graph::ReachableGraph& g = *in.graph;
  out.clusters_total = int(in.clusters->size());
  // An escape or a climb: a trajectory to a pose, not to a cluster, driven to its end.
  auto commit = [&](const char* reason) {
    climbing_ = false;
    adopt_move(in, out, reason, plan_opt_.climb_blind);
    return out;
  };
  auto commit_climb = [&](const char* reason) {
    commit(reason);
    climbing_ = true;
    climbing_axis_ = climb_axis_;
    return out;
  };
  // The target is a flight's foot (to_flight_foot): kept only by a kKeep.
  const bool flight_target = flight_target_;
  const bool next_flight = next_flight_;
  flight_target_ = next_flight_ = false;
  // A climb found while other frontiers are left: kept for last (climb_on's walk dropped).
  auto defer_climb = [&]() {
    --climbs_;
    deferred_climb_ = DeferredClimb{in.robot_foot_m, in.robot_yaw_rad,
                                    flight_target ? std::optional(flight_foot_) : std::nullopt,
                                    out.target_m, climb_partial_};
    out.trajectory = BsplineTrajectory{};
    out.path_m.clear();
    out.target_m = Eigen::Vector3d::Zero();
    out.target_yaw_rad = out.real_until_s = 0;
  };
  // The blind climb (PlanOptions::climb_blind), at most max_climbs times without a new target.
  auto try_climb = [&](bool on_flight_only, const FlightFoot* given = nullptr) {
    if (!plan_opt_.climb_blind || climbs_ >= opt_.max_climbs) return false;
    // PlanOptions::climb_axis_anew: at a partial climb's end, also up the axis the robot faces
    // now (a climb from a flight's foot along an axis 0.2 m off the flight's middle stopped on
    // it, and its walk on along that axis hit the flight's side wall: house seed 9).
    if (!climb_on(in, out, on_flight_only, given) &&
        !(plan_opt_.climb_axis_anew && on_flight_only && plan_opt_.flight_foot &&
          partial_climb_end(in.robot_foot_m) &&
          climb_on(in, out, on_flight_only, given, /*stored_axis=*/false)))
      return false;
    ++climbs_;
    return true;
  };
  // A floor away from the climb left for last (walked up a flight, not climbed blind): its floor
  // was left; the frontiers over that flight no longer wait for it.
  if (deferred_climb_ &&
      std::abs(in.robot_foot_m.z() - deferred_climb_->foot_m.z()) > plan_opt_.floor_change_dz_m) {
    deferred_climb_.reset();
  }
  for (FoundFlight& k : flights_found_)
    k.led_up = k.led_up || in.robot_foot_m.z() > k.foot.foot_m.z() + kFlightLedUpM;
  out.set_aside_expired = expire_set_aside(in);
  const bool stale = floor_stale(in);

  // No progress: the robot stood still with a target for no_progress_s. The target's cluster is
  // set aside and the robot steps away from what its body meets (an escape; else plans anew).
  bool stuck = false;
  if (no_progress(in)) {
    stuck = true;
    const Eigen::Vector3f hit = blocking_point(*in.view, robot_, in.robot_foot_m, in.robot_yaw_rad);
    if (const graph::FrontierCluster* tc = track_target(in); tc && !committed_)
      set_aside_cluster(in, *tc, SetAsideReason::kOverdue, hit);
    has_target_ = committed_ = flight_target_ = climb_start_ = false;
    if (free_start(in) && escape(in, out, &hit))
      return commit("escape: no progress, away from what the body meets");
  }

  // ---- Keep the current target unless there is a reason to replan.
  probe_mark(probe_, PlanStage::kLocalKeep);
  const char* reason = stuck ? "no progress" : "no target";
  int32_t kept_cluster = -1;  // the target's cluster at a periodic replan (target momentum)
  bool still_free = false;    // ... whose trajectory is still free (keep_on_failed_replan)
  if (has_target_) {
    const graph::FrontierCluster* tc = track_target(in);
    const double dxy = (in.robot_foot_m - target_m_).head<2>().norm();
    const double t_on = on_trajectory_s(in);
    // A flight's foot (and with flight_foot the foot of a climb left for last) is reached where
    // the climb can start: on it, or a second after the trajectory's end (the robot trails its
    // reference). (Back at a climb left for last "reached" 0.42 m short, 0.74 m before the first
    // riser, the climb found no flight ahead and the upper floor was never explored: house seed 9
    // with flight_foot, session 16.)
    const bool at_foot = flight_target || (climb_start_ && plan_opt_.flight_foot);
    const bool reached =
        (at_foot ? dxy <= 0.15 || (t_on >= current_.t_end() + 1.0 && dxy <= opt_.reached_radius_m)
                 : dxy <= opt_.reached_radius_m) &&
        std::abs(in.robot_foot_m.z() - target_m_.z()) < 0.5;
    // An escape or a climb runs to its end (a climb stopped half a metre short of its landing
    // leaves the body's rear over the flight).
    if (committed_ && (t_on >= current_.t_end() || dxy <= 0.1)) {
      reason = t_on > current_.t_end() + 3.0 ? "escape or climb overdue" : "escape or climb done";
      has_target_ = committed_ = false;
    } else if (climb_start_ && reached) {
      climb_start_ = false;
      std::optional<DeferredClimb> d = deferred_climb_;
      deferred_climb_.reset();
      if (try_climb(false, d && d->flight ? &*d->flight : nullptr))
        return commit_climb("climb on: the floor is done, up the flight left for last");
      // "Reached" short of its foot (the robot trailing its reference): walked to again, a bounded
      // number of times (teaching_building seed 4, session 39: 0.47 m short, no flight found
      // from there, "complete" with the floor above never explored).
      if (d && plan_opt_.flight_foot && dxy > 0.15 && ++d->misses < kMaxDeferredClimbMisses)
        deferred_climb_ = d;
      reason = "back at a flight left for last: no climb from here";
      has_target_ = false;
    } else if (!committed_ && !climb_start_ && reached && (tc || flight_target) &&
               try_climb(false, flight_target ? &flight_foot_ : nullptr)) {
      if (next_flight) return commit_climb("climb on: from the landing up the next flight");
      const int others = other_targets(in, tc ? tc->id : -1);
      if (others == 0)
        return commit_climb("climb on: a frontier on a flight is not seen from on it");
      if (climb_deferrals_ >= opt_.max_climb_deferrals)
        return commit_climb("climb on: left for last often enough, the floor's frontiers return");
      // With flight_foot, flights are found from more frontiers: a deferral counts only once the
      // floor is nearly done (office seed 1 climbed at 30 % coverage, floor 0 never finished).
      if (!plan_opt_.flight_foot || others <= opt_.climb_deferral_max_others) ++climb_deferrals_;
      defer_climb();  // other frontiers first: the climb is one way
      if (tc) set_aside_cluster(in, *tc, SetAsideReason::kStillFrontierAtTarget);
      reason = "climb left for last: other frontiers on this floor first";
      has_target_ = false;
    } else if (!committed_ && (reached || t_on > current_.t_end() + 3.0)) {
      if (climb_start_) deferred_climb_.reset();  // overdue on the way back to it: given up
      // Stood at the viewpoint (or should have long ago) and the cluster is still there. First
      // walk onto the frontier itself (the LiDAR's blind ring moves with the robot, so the
      // ground beyond a frontier is often only seen from on top of it); if it still persists,
      // it cannot be resolved from where the robot can stand: set it aside.
      if (tc) {
        const bool approached =
            std::find(approached_.begin(), approached_.end(), target_cluster_) != approached_.end();
        if (!flight_target && to_flight_foot(in, *tc, out)) return out;
        if (approached || !reached || flight_target) {
          set_aside_cluster(
              in, *tc, reached ? SetAsideReason::kStillFrontierAtTarget : SetAsideReason::kOverdue);
        } else {
          approached_.push_back(target_cluster_);
        }
      }
      reason = reached ? "target reached" : "target overdue";
      has_target_ = false;
    } else if (!tc && !committed_ && !climb_start_ && !flight_target) {
      // (A flight's foot is walked to even so: its frontier is often seen on the way, and the
      // climb from there is what reaches the floor above; teaching_building seed 1, session 22.)
      reason = "target cluster observed";
      has_target_ = false;
    } else {
      bool all_ignored = tc != nullptr;  // a committed escape or climb has no cluster
      if (tc)
        for (graph::NodeId n : tc->nodes) all_ignored = all_ignored && ignored(g.node(n).p_m);
      // On the plan-time check's sample grid: the same poses, so an unchanged map gives the same
      // answer (a pose grazing a nosing at the ground tolerance flipped between grids and the
      // same trajectory was planned, dropped and planned again forever).
      const auto pose_at = [&](double t) { return current_.pose(t); };
      const double t_from = std::clamp(t_on, current_.t_start(), current_.t_end());
      const CollisionHit hit =
          plan_opt_.climb_blind
              ? checker_.check_on_grid(*in.view, pose_at, current_.t_start(), current_.t_end(),
                                       t_from, current_.t_end() - t_from)
              : checker_.check_ahead(*in.view, pose_at, t_from,
                                     std::max(0.0, current_.t_end() - t_from), 0.0);
      if (all_ignored) {
        reason = "target set aside";
        has_target_ = false;
      } else if (hit.collides) {
        reason = "trajectory collides on the new map";
        has_target_ = false;
      } else if (!committed_ && !flight_target && !climb_start_ &&
                 in.t_s - planned_at_s_ >= opt_.replan_period_s) {
        // (Not a trip back to a climb left for last: replanned every period, its route flipped
        // between the two ways round a block of rooms and the robot never arrived;
        // teaching_building seed 4, session 39, 954-1012 s.)
        reason = "periodic replan";
        has_target_ = false;
        kept_cluster = tc ? tc->id : -1;
        periodic_ = plan_opt_.replan_only_if_faster && tc;
        still_free =
            plan_opt_.keep_on_failed_replan && tc && !climb_start_ && !retrying_ && !climbing_;
      } else {
        flight_target_ = flight_target;
        next_flight_ = next_flight;
        return keep_current(out, "");
      }
    }
  }
  out.replan_reason = reason;
  climb_start_ = false;
  if (retrying_) release_retry();  // the retry move ended: plan from the new vantage point
  // A climb (not a partial one) that ended at its planned height: the robot stands on the
  // landing it walked onto blind (landings()), also from a top tread level with it.
  if (climbing_ && !climb_partial_ &&
      std::abs(in.robot_foot_m.z() - current_.pose(current_.t_end()).foot_m.z()) <
          0.5 * robot_.step_height_m)
    ++landings_;
  // A climb dropped before the robot left the floor it started on (a collision predicted at the
  // foot) climbed nothing: with flight_foot it is not recorded (recorded, its flight's frontiers
  // up to the planned landing were ignored for good: house seed 1, session 14).
  if (climbing_ && plan_opt_.flight_foot &&
      in.robot_foot_m.z() <
          current_.pose(current_.t_start()).foot_m.z() + 0.5 * robot_.step_height_m)
    climbing_ = false;
  if (climbing_) {  // a climb ended (done, overdue, or dropped on a predicted collision)
    climbing_ = false;
    climb_deferrals_ = 0;
    deferred_climb_.reset();  // the floor is left (its frontiers over a flight no longer wait)
    lead_trip_.reset();
    climb_done_s_ = in.t_s;
    Eigen::Vector3f end = current_.pose(current_.t_end()).foot_m.cast<float>();
    bool partial = climb_partial_;
    // With flight_foot, a climb that ended away from its planned height is a partial climb ending
    // where the robot stands. Dropped more than a step below it (a collision predicted once the
    // treads ahead were mapped): recorded up to its planned "landing", the flight's frontiers above
    // the robot were ignored for good (test_stair seed 1: a "landing" mid-flight, dropped on the
    // first tread, the flight never climbed). More than 0.75 of a step over it: it took a tread
    // for its landing (the treads past it unseen, the body's space over it seen free), the robot
    // stands at the real landing's edge and the walk onto it is still to come (office seed 3 with
    // graph.close_probes_at_wall_faces, session 25: 0.2 m over the end, no node grew, "complete").
    const double dz_end = in.robot_foot_m.z() - end.z();
    if (plan_opt_.flight_foot &&
        (dz_end < -robot_.step_height_m || dz_end > 0.75 * robot_.step_height_m)) {
      end = in.robot_foot_m.cast<float>();
      partial = true;
    }
    const float top = end.z();
    ClimbedFlight f{{}, top, end, partial, climbing_axis_};
    for (double t = current_.t_start(); t <= current_.t_end(); t += 0.25) {
      const Eigen::Vector3f q = current_.pose(t).foot_m.cast<float>();
      if (q.z() < top - 0.05f) f.path_m.push_back(q);  // the flight, not the landing
    }
    climbed_.push_back(std::move(f));
    // Dropped on the flight (a wall seen ahead), or a partial climb: no node grows there; on up
    // from here.
    if (below_climbed_landing(in.robot_foot_m) && try_climb(true))
      return commit_climb("climb on: the climb stopped on the flight, on up it");
    // On a landing a flight rises from (a U-shaped stair's return flight): on up it first.
    // Otherwise the floor below, reachable again down the flight just climbed, drew the robot
    // back down to its frontiers (teaching_building seed 1, session 24).
    if (!partial && to_next_flight(in, out)) return out;
  }
  // The next flight's foot is seen from the landing but there is no way to it yet: the landing
  // under the robot, reached blind, is not in the map (no start support for the voxel search, no
  // graph node near). Wait there, trying again while the landing's map fills in, for at most
  // climb_settle_s. Else the floor below drew the robot back down the flight just climbed and
  // the floor above was never explored (teaching_building seed 3, session 39).
  if (next_flight_wait_until_s_ >= 0) {
    if (in.t_s < next_flight_wait_until_s_) {
      // (Not again in the cycle whose climb-end call started the wait: the same map.)
      // (The very expression that set it: exact, no rounding of a subtraction.)
      const bool started_now = in.t_s + opt_.climb_settle_s == next_flight_wait_until_s_;
      if (!started_now && to_next_flight(in, out)) return out;
      out.status = LocalPlanStatus::kSettling;
      return out;
    }
    next_flight_wait_until_s_ = -1;
  }
  // No other target left on this floor: back to the flight left for last, or up it from there.
  bool climb_escape = false;  // climb_last found no way back but an escape
  auto climb_last = [&]() {
    if (!deferred_climb_ || !plan_opt_.climb_blind) return false;
    const DeferredClimb d = *deferred_climb_;
    if ((in.robot_foot_m - d.foot_m).head<2>().norm() <= opt_.reached_radius_m &&
        std::abs(in.robot_foot_m.z() - d.foot_m.z()) < 0.5) {
      if (!plan_opt_.flight_foot) {
        deferred_climb_.reset();
        return try_climb(false, d.flight ? &*d.flight : nullptr);
      }
      if (try_climb(false, d.flight ? &*d.flight : nullptr)) {
        deferred_climb_.reset();
        return true;
      }
      // With flight_foot, near it but facing elsewhere, no flight ahead: to its pose, as from
      // afar (test_stair seed 1, session 17: 0.4 m from it facing away, the climb found no
      // flight, the deferral was dropped and the upper floor never explored). Bounded: a pose
      // from which no climb is ever found would be walked to forever.
      if (++deferred_climb_->misses >= kMaxDeferredClimbMisses) {
        deferred_climb_.reset();
        return false;
      }
    }
    SetAsideReason why = SetAsideReason::kAstarFailed;
    const bool ok = free_start(in) && ((d.flight && to_foot_of(in, *d.flight, out)) ||
                                       try_target(in, Viewpoint{d.foot_m, d.yaw_rad, graph::kNoId},
                                                  out, &why, Goal::kFlightFoot));
    if (!ok) {  // tried again next cycle (a B-spline through a door may fit from elsewhere)
      const int limit = plan_opt_.flight_foot ? opt_.max_climb_return_failures : 1;
      if (++deferred_climb_->failures >= limit) {
        deferred_climb_.reset();
        return false;
      }
      // Boxed in where the last target left the robot (it cannot turn, or the body hits an
      // obstacle next to it): step away first, as Stage 3 does.
      const bool near_hit = from_start_m(last_hit_m_) <= opt_.start_blame_radius_m;
      climb_escape = escape(in, out) || (near_hit && escape(in, out, &last_hit_m_));
      return climb_escape;
    }
    climb_start_ = true;
    return true;
  };
  auto to_climb = [&](const char* reason) {
    if (climb_escape) return commit("escape: boxed in on the way back to a flight left for last");
    if (!climb_start_) return commit_climb(reason);
    adopt_move(in, out, "back to the flight left for last: no other target on this floor", false);
    return out;
  };

  // No target: first a flight found here that never led up (to_found_flight); then the verdict,
  // except just after a climb, when the new floor's graph is still growing (teaching_building
  // seed 3, session 39: "complete" 5 s after a climb onto a U-shaped stair's landing, the floor
  // above never explored).
  auto no_target = [&](LocalPlanStatus s) -> LocalPlanResult& {
    if (to_found_flight(in, out)) return out;
    const bool settling = climb_done_s_ >= 0 && in.t_s - climb_done_s_ < opt_.climb_settle_s;
    out.status = settling ? LocalPlanStatus::kSettling : s;
    return out;
  };

  // ---- Stage 1: TSP over the cluster representatives (graph path costs).
  probe_mark(probe_, PlanStage::kLocalStage1);
  // Frontiers remain but the graph has stopped growing: they cannot be resolved from this floor
  // (PlanOptions::stale_floor_s); the climb left for last is taken.
  if (stale && deferred_climb_ && climb_last())
    return to_climb("climb on: the floor's graph stopped growing, up the flight left for last");
  // ... or, with no climb left for last, a flight that rises out of reach (teaching_building
  // seed 1, session 23: frontiers kept coming back near the stair hub, the floor was never without
  // a target before 1800 s, and its one stair was never climbed).
  if (stale && !deferred_climb_ && to_flight_lead(in, out, true)) return out;
  if (in.clusters->empty()) {
    if (try_climb(true)) return commit_climb("climb on: no frontier, standing on a flight");
    if (climb_last()) return to_climb("climb on: no frontier, up the flight left for last");
    if (to_flight_lead(in, out)) return out;
    return no_target(LocalPlanStatus::kNoFrontiers);
  }
  if (!sg_fresh_) build_search_graph(g);
  uint32_t robot_node = g.root();
  if (robot_node == graph::kNoId || !g.node(robot_node).alive)
    robot_node = g.nearest(in.robot_foot_m.cast<float>(), 1.5f, 1.0f);
  // A robot's node without edges yet (new under the robot a step above the node it came from,
  // GraphOptions::root_off_graph). Just after a blind climb it is the new floor's first node:
  // wait for the graph to grow from it (the nodes below are the flight's, not a way on). Else
  // search from the nearest linked node while one is near.
  if (robot_node != graph::kNoId && g.node(robot_node).degree == 0) {
    if (climb_done_s_ >= 0 && in.t_s - climb_done_s_ < opt_.climb_settle_s) {
      out.status = LocalPlanStatus::kNoRobotNode;
      return out;
    }
    const graph::NodeId linked = linked_node_near(g, in.robot_foot_m.cast<float>(), 1.5f, 1.0f);
    if (linked != graph::kNoId) robot_node = linked;
  }
  if (robot_node == graph::kNoId) {
    out.status = LocalPlanStatus::kNoRobotNode;
    return out;
  }
  robot_node_ = robot_node;
  {
    std::vector<graph::NodeId> near;
    g.nodes_within(in.robot_foot_m.cast<float>(), 3.0f, 1.0f, near);
    std::vector<std::pair<float, graph::NodeId>> by_d;
    for (graph::NodeId n : near)
      if (g.node(n).alive && g.node(n).state == graph::ElementState::kConfirmed)
        by_d.push_back({(g.node(n).p_m - in.robot_foot_m.cast<float>()).squaredNorm(), n});
    std::sort(by_d.begin(), by_d.end());
    start_nodes_m_.clear();
    for (size_t k = 0; k < by_d.size() && k < 3; ++k)
      start_nodes_m_.push_back(g.node(by_d[k].second).p_m.cast<double>());
  }
  search_.dijkstra(sg_, std::span<const uint32_t>(&robot_node, 1));
  std::vector<Candidate> cands, off_graph;  // off_graph: no path along G_real
  std::vector<double> cand_dist;
  // PlanOptions::floor_first: clusters off the robot's level (up a ramp, on a landing) wait until
  // it has no other; once its graph stopped growing, they go first (the rest do not resolve).
  std::vector<Candidate> later;
  std::vector<double> later_dist;
  for (size_t ci = 0; ci < in.clusters->size(); ++ci) {
    const graph::FrontierCluster& c = (*in.clusters)[ci];
    uint32_t rep = graph::kNoId;
    float best = std::numeric_limits<float>::infinity();
    bool any = false;
    for (graph::NodeId n : c.nodes) {
      if (ignored(g.node(n).p_m)) continue;
      any = true;
      const float d = (g.node(n).p_m - c.centroid_m).squaredNorm();
      if (d < best) best = d, rep = n;
    }
    if (!any) {
      ++out.clusters_set_aside;
      continue;
    }
    const double d = search_.dist(rep);
    if (!std::isfinite(d)) {
      ++out.clusters_unreachable;
      off_graph.push_back({c.id, ci, rep});
      continue;
    }
    if (plan_opt_.floor_first &&
        std::abs(double(g.node(rep).p_m.z()) - in.robot_foot_m.z()) > plan_opt_.floor_node_band_m) {
      later.push_back({c.id, ci, rep});
      later_dist.push_back(d);
      continue;
    }
    cands.push_back({c.id, ci, rep});
    cand_dist.push_back(d);
  }
  if (cands.empty() || (stale && !later.empty())) cands.swap(later), cand_dist.swap(later_dist);
  if (cands.empty()) {
    if (try_climb(true))
      return commit_climb("climb on: no reachable frontier, standing on a flight");
    if (climb_last())
      return to_climb("climb on: no reachable frontier, up the flight left for last");
    if (to_off_graph(in, off_graph, out)) return out;
    if (retry_from_elsewhere(in, out)) return out;
    if (to_flight_lead(in, out)) return out;
    return no_target(LocalPlanStatus::kNoReachableTarget);
  }
  // The nearest clusters (by graph distance) enter the TSP (PlanOptions::tsp_max_clusters); the
  // rest wait for later cycles.
  std::vector<size_t> idx(cands.size());
  for (size_t i = 0; i < idx.size(); ++i) idx[i] = i;
  std::stable_sort(idx.begin(), idx.end(),
                   [&](size_t a, size_t b) { return cand_dist[a] < cand_dist[b]; });
  if (int(idx.size()) > plan_opt_.tsp_max_clusters) idx.resize(size_t(plan_opt_.tsp_max_clusters));
  std::vector<Candidate> sel;
  for (size_t i : idx) sel.push_back(cands[i]);

  const bool with_anchor = in.anchor_m.has_value();
  uint32_t anchor_node = graph::kNoId;
  if (with_anchor) anchor_node = g.nearest(in.anchor_m->cast<float>(), 3.0f, 1.5f);
  const int n = int(sel.size()) + 1 + (anchor_node != graph::kNoId ? 1 : 0);
  std::vector<uint32_t> nodes_of(static_cast<size_t>(n), 0u);
  nodes_of[0] = robot_node;
  for (size_t i = 0; i < sel.size(); ++i) nodes_of[i + 1] = sel[i].rep;
  if (anchor_node != graph::kNoId) nodes_of[size_t(n - 1)] = anchor_node;
  std::vector<double> cost(size_t(n) * size_t(n), 0.0);
  for (int i = 0; i < n; ++i)
    search_.costs_from(sg_, nodes_of[size_t(i)], nodes_of,
                       std::span<double>(cost.data() + size_t(i) * size_t(n), size_t(n)));
  const TspResult tour =
      tsp_.solve(CostMatrix{n, cost}, 0, anchor_node != graph::kNoId ? n - 1 : -1);
  std::vector<size_t> order;  // indices into sel
  if (tour.status == TspStatus::kOk) {
    for (int k : tour.order)
      if (k > 0 && k <= int(sel.size())) order.push_back(size_t(k - 1));
  } else {
    for (size_t i = 0; i < sel.size(); ++i) order.push_back(i);  // by distance
  }
  if (plan_opt_.target_momentum && kept_cluster >= 0)
    for (size_t i = 0; i < sel.size(); ++i)
      if (sel[i].cluster_id == kept_cluster)
        keep_first_in_tour(i, cost, n, anchor_node != graph::kNoId, opt_.keep_target_margin_m,
                           opt_.keep_target_margin_frac, order);
  for (size_t k : order) out.cluster_order.push_back(sel[k].cluster_id);

  // ---- Stage 2: one viewpoint per cluster over the window W (Eq. 6).
  probe_mark(probe_, PlanStage::kLocalStage2);
  const size_t w = std::min(order.size(), size_t(std::max(1, plan_opt_.window_w)));
  std::vector<std::vector<Viewpoint>> window;
  for (size_t m = 0; m < w; ++m) window.push_back(viewpoints_of(in, sel[order[m]]));
  std::map<std::pair<uint32_t, uint32_t>, double> memo;
  const ViewpointDistance d = [&](const Viewpoint& a, const Viewpoint& b) {
    if (a.node == b.node) return (a.p_m - b.p_m).norm();
    if (a.node >= sg_.num_nodes() || b.node >= sg_.num_nodes()) return (a.p_m - b.p_m).norm() * 1.5;
    const auto key = std::make_pair(std::min(a.node, b.node), std::max(a.node, b.node));
    auto it = memo.find(key);
    if (it != memo.end()) return it->second;
    const PathResult r = pair_search_.astar(sg_, a.node, b.node);
    const double c = r.found ? r.cost : kUnreachable;
    memo.emplace(key, c);
    return c;
  };
  const Viewpoint x0{in.robot_foot_m, in.robot_yaw_rad, robot_node};
  std::optional<Viewpoint> anchor;
  if (anchor_node != graph::kNoId) anchor = Viewpoint{in.anchor_m.value(), 0.0, anchor_node};
  const DpResult dp = dp_.solve(x0, window, anchor, d);

  // ---- Stage 3: voxel A* + B-spline to the first viewpoint; on failure the cluster's other
  // candidates, then the next clusters (bounded).
  probe_mark(probe_, PlanStage::kLocalStage3);
  if (!free_start(in)) {  // boxed in on the map: no cluster is to blame
    out.status = LocalPlanStatus::kStartBlocked;
    return out;
  }
  int attempts = 0;
  struct Failed {
    size_t m;  // index into order
    SetAsideReason why;
    Eigen::Vector3f hit_m;
  };
  std::vector<Failed> failed;
  // At a periodic replan, Stage 3 failed for the target's own cluster (or for every cluster):
  // the trajectory followed was checked free on this map above, so it stays
  // (PlanOptions::keep_on_failed_replan). Maze seed 1, session 26: from a corner of a narrow
  // passage a new B-spline found no room to turn that the walk itself did not need; each such
  // replan escaped or turned back to another cluster, and the one beyond was never reached.
  const auto keep_followed = [&]() -> LocalPlanResult& {
    has_target_ = true;
    next_flight_ = next_flight;
    planned_at_s_ = in.t_s;
    return keep_current(out, "periodic replan found no trajectory: the one followed is still free");
  };
  for (size_t m = 0; m < order.size() && attempts < opt_.max_stage3_attempts; ++m) {
    const Candidate& c = sel[order[m]];
    std::vector<Viewpoint> vps = m < window.size() ? window[m] : viewpoints_of(in, c);
    if (m == 0 && dp.status == DpStatus::kOk && !dp.choice.empty())
      std::rotate(vps.begin(), vps.begin() + dp.choice[0], vps.begin() + dp.choice[0] + 1);
    bool ok = false;
    SetAsideReason why = SetAsideReason::kAstarFailed;
    for (size_t k = 0; k < vps.size() && attempts < opt_.max_stage3_attempts && !ok;
         ++k, ++attempts)
      ok = try_target(in, vps[k], out, &why, Goal::kClusterView);
    if (ok) {
      adopt_target(in, (*in.clusters)[c.cluster_index], out);
      return out;
    }
    failed.push_back({m, why, last_hit_m_});
    if (still_free && c.cluster_id == kept_cluster) return keep_followed();
  }
  if (!failed.empty() && still_free) return keep_followed();
  // Every attempt failed. If the robot cannot turn where it stands (a dead end narrower than
  // the body's turning circle: every path back starts with a turn), the clusters are not to
  // blame: step straight to the nearest pose where it can turn, and plan again from there.
  std::optional<LocalPlanResult> climb_deferred;  // the climb deferred here, taken up below
  if (!failed.empty() && try_climb(true)) {
    if (!other_targets(in, -1))
      return commit_climb("climb on: no way to a frontier, standing on a flight");
    climb_deferred = out;
    defer_climb();  // other frontiers may become reachable from elsewhere
  }
  if (!failed.empty() && escape(in, out)) return commit("escape: cannot turn here");
  // Every attempt's body hit an obstacle next to the start: the start is boxed in (it faces a
  // wall, or stands by a wall end it cannot curve away from), not the clusters: step away from
  // the nearest of those obstacles and plan again from there.
  bool boxed_in = !failed.empty();
  Eigen::Vector3f hit = kNoHitM;
  double hit_d = std::numeric_limits<double>::infinity();
  for (const Failed& f : failed) {
    const double d = from_start_m(f.hit_m);
    boxed_in = boxed_in && d <= opt_.start_blame_radius_m;
    if (d < hit_d) hit_d = d, hit = f.hit_m;
  }
  if (boxed_in && start_escapes_ < opt_.max_start_escapes && escape(in, out, &hit)) {
    ++start_escapes_;
    return commit("escape: boxed in by an obstacle next to the start");
  }
  // Every body hit within 2.5 m, none above the robot (office seed 4: from the landing, 1.1 m
  // down the flight against the stairwell's side): if a flight goes down from here, it is the
  // way to all of them.
  bool hits_near = !failed.empty();
  for (const Failed& f : failed)
    hits_near = hits_near && from_start_m(f.hit_m) <= 2.5 &&
                f.hit_m.z() < in.robot_foot_m.z() + robot_.step_height_m;
  // With flight_foot not with a target on the robot's own level (test_stair seed 3, session 16:
  // boxed in on the landing with a frontier of the upper floor beside it, the robot walked down
  // to the floor and the upper floor was left at 13 %).
  bool off_level = !failed.empty();
  for (const Failed& f : failed)
    off_level = off_level && std::abs(g.node(sel[order[f.m]].rep).p_m.z() - in.robot_foot_m.z()) >
                                 robot_.step_height_m;
  const bool way_down_blocked = (boxed_in || hits_near) && (off_level || !plan_opt_.flight_foot);
  if (way_down_blocked && plan_opt_.climb_blind && descents_ < 2 && descend_flight(in, out)) {
    ++descents_;
    return commit("descend: boxed in on a flight, straight down its axis to the floor below");
  }
  // On a flight, every way down blocked (as above), no escape and no descent (none found, or two
  // tried already): up the flight is the way on. Deferred, the frontiers below were set aside
  // one by one until "complete" (teaching_building seed 3, session 39: mid-way up a U-shaped
  // stair's first flight, every trajectory hit the tread behind, the floor above never explored).
  if (climb_deferred && way_down_blocked) {
    deferred_climb_.reset();
    ++climbs_;  // defer_climb() gave it back
    out = std::move(*climb_deferred);
    return commit_climb("climb on: no way down the flight, up it");
  }
  // Stage 3 failed for these clusters: after max_failures cycles a cluster is set aside.
  for (const auto& [m, why, hit_m] : failed) {
    const Candidate& c = sel[order[m]];
    auto it = std::find_if(failures_.begin(), failures_.end(),
                           [&](const auto& f) { return f.first == c.cluster_id; });
    if (it == failures_.end()) it = failures_.insert(failures_.end(), {c.cluster_id, 0});
    if (++it->second >= opt_.max_failures) {
      if (to_flight_foot(in, (*in.clusters)[c.cluster_index], out)) {
        failures_.erase(it);
        return out;
      }
      set_aside_cluster(in, (*in.clusters)[c.cluster_index], why, hit_m);
      failures_.erase(it);
    }
  }
  if (climb_last()) return to_climb("climb on: no way to a frontier, up the flight left for last");
  const bool left = std::any_of(cands.begin(), cands.end(), [&](const Candidate& c) {
    const auto& nodes = (*in.clusters)[c.cluster_index].nodes;
    return std::any_of(nodes.begin(), nodes.end(),
                       [&](graph::NodeId n) { return !ignored(g.node(n).p_m); });
  });
  if (!left && retry_from_elsewhere(in, out)) return out;
  if (!left && to_flight_lead(in, out)) return out;
  return no_target(LocalPlanStatus::kNoReachableTarget);
}

}  // namespace storey::core::plan
