#include "core/plan/exploration_planner.hpp"

#include <algorithm>
#include <cmath>

#include "core/plan/escape.hpp"
#include "core/plan/path_centring.hpp"
#include "core/plan/plan_config.hpp"

namespace storey::core::plan {

std::vector<uint8_t> guided_clusters(const HybridGraph& hg, std::span<const int32_t> first_zones,
                                     uint32_t robot_node, double near_m,
                                     const std::vector<graph::FrontierCluster>& clusters,
                                     GraphSearch& search) {
  // Within near_m along G_real (hypothetical edges excluded): the robot's neighbourhood as seen.
  if (near_m > 0)
    search.dijkstra(hg.search_graph(), std::span<const uint32_t>(&robot_node, 1), near_m,
                    [&](uint32_t e, uint32_t, uint32_t) { return hg.csr_edge_real(e); });
  std::vector<uint8_t> take(clusters.size(), 0);
  for (size_t ci = 0; ci < clusters.size(); ++ci)
    for (graph::NodeId n : clusters[ci].nodes) {
      const uint32_t u = hg.node_of_real(n);
      if (u == kNoNode) continue;
      const bool first = std::find(first_zones.begin(), first_zones.end(), hg.nodes()[u].zone) !=
                         first_zones.end();
      if (first || (near_m > 0 && std::isfinite(search.dist(u)))) {
        take[ci] = 1;
        break;
      }
    }
  return take;
}

namespace {
// The local layer produced (or kept) a trajectory: it becomes the planner's result.
void take_trajectory(LocalPlanResult& lr, ExplorationResult& r) {
  r.status = lr.status == LocalPlanStatus::kKeep ? ExplorationStatus::kKeep
                                                 : ExplorationStatus::kNewTrajectory;
  r.reason = lr.replan_reason;
  r.trajectory = std::move(lr.trajectory);
  r.real_until_s = lr.real_until_s;
  r.target_m = lr.target_m;
  r.target_yaw_rad = lr.target_yaw_rad;
  r.target_cluster = lr.target_cluster;
}
}  // namespace

const char* to_string(PlanStage s) {
  static constexpr const char* kNames[] = {
      "floors",         "prior",        "prior_zones", "hybrid_bind", "hybrid_check",
      "hybrid_compile", "hybrid_zones", "global",      "local_keep",  "local_stage1",
      "local_stage2",   "local_stage3", "approach",    "done"};
  static_assert(sizeof(kNames) / sizeof(kNames[0]) == size_t(PlanStage::kCount));
  return size_t(s) < size_t(PlanStage::kCount) ? kNames[size_t(s)] : "?";
}

void ExplorationPlanner::set_stage_probe(StageProbe* probe) {
  probe_ = probe;
  hybrid_.set_stage_probe(probe);
  local_.set_stage_probe(probe);
}

const char* to_string(ExplorationStatus s) {
  switch (s) {
    case ExplorationStatus::kNewTrajectory:
      return "new_trajectory";
    case ExplorationStatus::kKeep:
      return "keep";
    case ExplorationStatus::kExploring:
      return "exploring";
    case ExplorationStatus::kComplete:
      return "complete";
    case ExplorationStatus::kFailed:
      return "failed";
  }
  return "?";
}

namespace {
FloorTrackerOptions floor_options(const PlanOptions& o) {
  FloorTrackerOptions f;
  f.floor_change_dz_m = o.floor_change_dz_m;
  f.stable_s = o.floor_stable_s;
  f.stable_band_m = o.floor_stable_band_m;
  f.stable_travel_m = o.floor_stable_travel_m;
  f.node_band_m = o.floor_node_band_m;
  return f;
}
}  // namespace

ExplorationPlanner::ExplorationPlanner(const RobotModel& robot, const PlanOptions& options,
                                       double voxel_size_m, const LocalPlannerOptions& local)
    : robot_(robot),
      opt_(options),
      floors_(floor_options(options)),
      clearance_(options.zone_clearance_radius_m),
      global_(tsp_options(options)),
      local_(robot, options, voxel_size_m, local),
      astar_(astar_options(options)),
      builder_(robot, trajectory_options(options)),
      checker_(robot, voxel_size_m) {}

void ExplorationPlanner::update_floor_progress(const graph::ReachableGraph& g) {
  node_z_.clear();
  for (graph::NodeId i = 0; i < g.node_capacity(); ++i)
    if (g.node(i).alive) node_z_.push_back(g.node(i).p_m.z());
  floors_.refine(node_z_);
  const size_t nf = floors_.floors().size();
  floor_nodes_.assign(nf, 0);
  floor_frontiers_.assign(nf, 0);
  for (graph::NodeId i = 0; i < g.node_capacity(); ++i) {
    const graph::GraphNode& n = g.node(i);
    if (!n.alive) continue;
    const int32_t f = floors_.floor_of(n.p_m.z());
    if (f < 0) continue;
    ++floor_nodes_[size_t(f)];
    floor_frontiers_[size_t(f)] += n.frontier();
  }
  for (size_t f = 0; f < nf; ++f) {
    Floor& fl = floors_.floor(int32_t(f));
    fl.open_ratio = floor_nodes_[f] ? double(floor_frontiers_[f]) / double(floor_nodes_[f]) : 1.0;
    // A visited floor with nodes and no frontier left is explored (Sec. IV: completion).
    if (floor_nodes_[f] > 0 && floor_frontiers_[f] == 0) fl.explored = true;
  }
}

void ExplorationPlanner::build_prior(const ExplorationInput& in, int32_t ref, int32_t target,
                                     ExplorationResult& r) {
  const graph::ReachableGraph& g = *in.graph;
  // The reference floor's part of G_real as a compact graph.
  std::vector<uint32_t> index(g.node_capacity(), kNoNode);
  std::vector<Eigen::Vector3d> pos;
  std::vector<double> clear;
  std::vector<Eigen::Vector3f> support;
  for (graph::NodeId i = 0; i < g.node_capacity(); ++i) {
    const graph::GraphNode& n = g.node(i);
    if (!n.alive || floors_.floor_of(n.p_m.z()) != ref) continue;
    index[i] = uint32_t(pos.size());
    pos.push_back(n.p_m.cast<double>());
    support.push_back(n.p_m);
  }
  clearance_(*in.view, support, clear);  // batched: columns shared between nodes
  std::vector<SearchGraph::Edge> edges;
  for (graph::EdgeId e = 0; e < g.edge_capacity(); ++e) {
    const graph::GraphEdge& ge = g.edge(e);
    if (!ge.alive || index[ge.a] == kNoNode || index[ge.b] == kNoNode) continue;
    edges.push_back({index[ge.a], index[ge.b], double(ge.length_m)});
  }
  probe_mark(probe_, PlanStage::kPriorZones);
  const SearchGraph sg = SearchGraph::from_edges(pos, edges, true);
  const ZonePartition zones = partitioner_.partition(sg, clear, {opt_.r_z_m, opt_.min_zone_nodes});
  r.dz_m = floors_.dz(ref, target);
  hybrid_.init_prior(sg, zones, r.dz_m, target);
  set_aside_zones_.clear();
  r.prior_built = true;
}

bool ExplorationPlanner::drive_to(const ExplorationInput& in, const Eigen::Vector3d& goal,
                                  ExplorationResult& r) {
  // PlanOptions::keep_zone_drive: the drive to the same goal is kept while its reference has more
  // than a second to go. Each cycle's new drive started at rest where the robot was: the
  // reference never got up to speed, and the robot crawled toward the zone centre at 0.2-0.4 m/s
  // (house seed 2, session 32: a new trajectory every 0.5 s for 18 s). Up to speed, the robot
  // needs the next drive (another goal) to start where its braking ends (below).
  const double now = in.t_s - std::clamp(in.trajectory_lag_s, 0.0, LocalPlanner::kMaxReferenceLagS);
  if (opt_.keep_zone_drive && drive_end_s_ >= 0 && now < drive_end_s_ - 1.0 &&
      (goal - drive_goal_m_).norm() < 0.3) {
    r.status = ExplorationStatus::kKeep;
    return true;
  }
  // With keep_zone_drive and brake_start, a moving robot's new drive starts where it comes to rest
  // (as LocalPlanner::brake_start, straight along the velocity): started where the robot was, a
  // drive entered at walking speed was overshot by 0.45 m (house seed 3, session 32).
  Eigen::Vector3d start = in.robot_foot_m;
  if (opt_.keep_zone_drive && opt_.brake_start && in.robot_velocity_mps.allFinite())
    if (const auto rest = straight_rest_point(checker_, *in.view, robot_, in.robot_foot_m,
                                              in.robot_yaw_rad, in.robot_velocity_mps, in.t_s))
      start = *rest;
  VoxelPath path = astar_.plan(*in.view, start, goal);
  if (path.status != VoxelAStarStatus::kOk || path.points_m.empty()) return false;
  path.points_m.front() = start;
  const Eigen::Vector2d d = (goal - start).head<2>();
  const double yaw = shape_path(*in.view, path.points_m,
                                d.norm() > 1e-6 ? std::atan2(d.y(), d.x()) : in.robot_yaw_rad);
  TrajectoryResult tr =
      builder_.build(*in.view, checker_, path.points_m, in.robot_yaw_rad, yaw, in.t_s);
  if (tr.status != TrajectoryStatus::kOk && tr.status != TrajectoryStatus::kPolyline) return false;
  r.trajectory = std::move(tr.trajectory);
  r.real_until_s = r.trajectory.t_end();  // the goal is the end of the real prefix
  r.target_m = goal;
  r.target_yaw_rad = yaw;
  r.status = ExplorationStatus::kNewTrajectory;
  local_.drop_target();
  drive_goal_m_ = goal;
  drive_end_s_ = r.trajectory.t_end();
  drove_ = true;
  return true;
}

ExplorationResult ExplorationPlanner::plan(const ExplorationInput& in) {
  probe_mark(probe_, PlanStage::kFloors);
  drove_ = false;
  ExplorationResult r = plan_cycle(in);
  // Any other trajectory published replaces the drive: a later drive is planned anew.
  if (r.status == ExplorationStatus::kNewTrajectory && !drove_) drive_end_s_ = -1.0;
  probe_mark(probe_, PlanStage::kDone);
  return r;
}

ExplorationResult ExplorationPlanner::plan_cycle(const ExplorationInput& in) {
  ExplorationResult r;
  if (!in.view || !in.graph || !in.clusters || !in.viewpoints || !in.robot_foot_m.allFinite() ||
      !std::isfinite(in.t_s)) {
    r.reason = "bad input (null pointer or non-finite pose/time)";
    hybrid_updated_last_ = false;  // its changed regions are not seen by the maintenance
    return r;
  }
  const graph::ReachableGraph& g = *in.graph;
  // 1) Floors.
  r.floor_changed = floors_.update(in.robot_foot_m, in.t_s);
  update_floor_progress(g);
  r.floor = floors_.current();
  // 2) Prior on arrival on a new floor (Sec. IV-A).
  if (r.floor_changed && floors_.is_new_floor() && opt_.use_prior && r.floor >= 0) {
    const int32_t ref = floors_.choose_reference(r.floor);
    if (ref >= 0) {
      r.reference_floor = ref;
      probe_mark(probe_, PlanStage::kPrior);
      build_prior(in, ref, r.floor, r);
    }
  }
  // 3) Maintenance (Sec. IV-B) and 4) global guidance (Sec. IV-C) on the prior's target floor.
  LocalPlanInput li;
  li.view = in.view;
  li.graph = in.graph;
  li.clusters = in.clusters;
  li.viewpoints = in.viewpoints;
  li.robot_foot_m = in.robot_foot_m;
  li.robot_yaw_rad = in.robot_yaw_rad;
  li.robot_velocity_mps = in.robot_velocity_mps;
  li.t_s = in.t_s;
  li.trajectory_lag_s = in.trajectory_lag_s;
  bool zones_left = false;
  // An escape or a climb under way is driven to its end before guidance picks a zone (a climb
  // onto a landing ends on the new floor, where the prior is built on arrival).
  const bool on_target =
      hybrid_.has_prior() && hybrid_.target_floor() == r.floor && !local_.committed();
  if (!on_target) hybrid_updated_last_ = false;
  if (on_target) {
    // Changed regions only count if the previous cycle's maintenance saw the ones before.
    const std::vector<graph::Aabb>* changed = hybrid_updated_last_ ? in.changed_regions : nullptr;
    r.maintenance =
        hybrid_.update(*in.view, in.map_version, g, floors_, in.robot_foot_m, opt_, changed);
    hybrid_updated_last_ = true;
    for (const HybridZone& z : hybrid_.zones())
      r.zones.push_back({z.id, z.state, hybrid_.nodes()[z.centre].p_m, int(z.nodes.size()),
                         z.real_nodes, z.hyp_nodes, z.frontier_nodes});
    const uint32_t robot_node = g.root() == graph::kNoId ? kNoNode : hybrid_.node_of_real(g.root());
    if (robot_node != kNoNode) {
      auto aside = [&](int32_t id) {
        return std::find(set_aside_zones_.begin(), set_aside_zones_.end(), id) !=
               set_aside_zones_.end();
      };
      probe_mark(probe_, PlanStage::kGlobal);
      const GlobalPlan gp = global_.plan(hybrid_, robot_node, aside);
      r.zone_sequence = gp.zone_order;
      r.zones_deferred = gp.deferred;
      zones_left = !gp.zone_order.empty();
      if (zones_left) {
        r.guided = true;
        // Clusters of the first guidance_zones zones; anchor = centre of the next zone.
        const size_t first =
            std::min(gp.zone_order.size(), size_t(std::max(1, opt_.guidance_zones)));
        sel_clusters_.clear();
        sel_viewpoints_.clear();
        const std::vector<uint8_t> take =
            guided_clusters(hybrid_, std::span<const int32_t>(gp.zone_order.data(), first),
                            robot_node, opt_.guidance_near_m, *in.clusters, near_search_);
        for (size_t ci = 0; ci < in.clusters->size(); ++ci) {
          if (!take[ci]) continue;
          const graph::FrontierCluster& c = (*in.clusters)[ci];
          sel_clusters_.push_back(c);
          for (const graph::ClusterViewpoints& v : *in.viewpoints)
            if (v.cluster_id == c.id) sel_viewpoints_.push_back(v);
        }
        auto centre_of = [&](int32_t id) {
          for (const HybridZone& z : hybrid_.zones())
            if (z.id == id) return z.centre;
          return kNoNode;
        };
        if (first < gp.zone_order.size())
          li.anchor_m = hybrid_.nodes()[centre_of(gp.zone_order[first])].p_m;
        if (!sel_clusters_.empty()) {
          li.clusters = &sel_clusters_;
          li.viewpoints = &sel_viewpoints_;
          li.all_clusters = in.clusters;
          LocalPlanResult lr = local_.plan(li);
          if (lr.status == LocalPlanStatus::kNewTrajectory || lr.status == LocalPlanStatus::kKeep) {
            r.cluster_order = std::move(lr.cluster_order);
            take_trajectory(lr, r);
            return r;
          }
        }
        // No cluster to serve in the first zones: follow the real prefix toward the first
        // zone's centre (Sec. IV-C). A prefix ending at the robot cannot make progress.
        probe_mark(probe_, PlanStage::kApproach);
        const int32_t z0 = gp.zone_order.front();
        const Approach a = global_.approach(hybrid_, robot_node, centre_of(z0));
        const bool progress =
            a.ok && a.real_prefix > 1 && (a.goal_m - in.robot_foot_m).head<2>().norm() > 0.75;
        if (progress && drive_to(in, a.goal_m, r)) {
          r.reason = a.used_hybrid ? "toward a hypothetical zone (real prefix)"
                                   : "toward the next zone centre";
          return r;
        }
        set_aside_zones_.push_back(z0);  // seen from as close as the real graph gets
        li.anchor_m.reset();
        li.clusters = in.clusters;
        li.viewpoints = in.viewpoints;
        li.all_clusters = nullptr;
        zones_left = gp.zone_order.size() > 1;
      }
    }
  }
  // 5) Local layer over every cluster (first floor, no prior, or guidance had nothing to do).
  li.last_resort = true;
  LocalPlanResult lr = local_.plan(li);
  r.cluster_order = std::move(lr.cluster_order);
  switch (lr.status) {
    case LocalPlanStatus::kNewTrajectory:
    case LocalPlanStatus::kKeep:
      take_trajectory(lr, r);
      return r;
    case LocalPlanStatus::kNoRobotNode:
      r.status = ExplorationStatus::kExploring;
      r.reason = "no graph node at the robot yet";
      return r;
    case LocalPlanStatus::kStartBlocked:  // the body overlaps an obstacle: not "complete"
      r.status = ExplorationStatus::kExploring;
      r.reason = "no collision-free start pose near the robot";
      return r;
    case LocalPlanStatus::kSearching:  // bounded work: more to try next cycle, not "complete"
      r.status = ExplorationStatus::kExploring;
      r.reason = "targets left to try next cycle";
      return r;
    case LocalPlanStatus::kSettling:  // just climbed: the new floor's graph is still growing
      r.status = ExplorationStatus::kExploring;
      r.reason = "after a climb, waiting for the new floor's graph";
      return r;
    case LocalPlanStatus::kBadInput:
      r.status = ExplorationStatus::kFailed;
      r.reason = "local planner rejected the input";
      return r;
    case LocalPlanStatus::kNoFrontiers:
    case LocalPlanStatus::kNoReachableTarget:
      break;
  }
  // 6) Completion (Sec. IV): no reachable frontier anywhere (G_real spans every floor) and no
  // uncompleted zone left on the prior's floor.
  if (zones_left) {
    r.status = ExplorationStatus::kExploring;
    r.reason = "uncompleted zones left, no target this cycle";
    return r;
  }
  if (r.floor >= 0) floors_.floor(r.floor).explored = true;
  r.status = ExplorationStatus::kComplete;
  r.reason = lr.status == LocalPlanStatus::kNoFrontiers
                 ? "no frontier and no uncompleted zone left on any floor"
                 : "no reachable, observable frontier and no uncompleted zone left on any floor";
  return r;
}

}  // namespace storey::core::plan
