#include "firmware/autonomy.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>

namespace storey::firmware {

const char* to_string(ExplorationState s) {
  switch (s) {
    case ExplorationState::kStarting:
      return "starting";
    case ExplorationState::kExploring:
      return "exploring";
    case ExplorationState::kComplete:
      return "complete";
    case ExplorationState::kStranded:
      return "stranded";
  }
  return "unknown";
}

std::string describe_target(const ExplorationStatus& s) {
  if (!s.has_target) return {};
  char b[96];
  if (s.target_cluster >= 0)
    std::snprintf(b, sizeof b, "  -> cluster %d at %.1f, %.1f, %.1f", s.target_cluster,
                  s.target_x_m, s.target_y_m, s.target_z_m);
  else
    std::snprintf(b, sizeof b, "  -> goal at %.1f, %.1f, %.1f", s.target_x_m, s.target_y_m,
                  s.target_z_m);
  return b;
}

namespace {
constexpr const char* kTaskNames[] = {"ingest", "map", "plan", "control", "watchdog", "telemetry"};

// The LiDAR cannot see the ground within h / tan(-v_min) of the robot (VLP-16 at 0.5 m: 1.9 m),
// so at start-up there is no observed support under the feet. The reachable-set seed search and
// the graph's root search (which probes at half its radius) must reach past that blind ring.
AutonomyOptions widen_for_blind_zone(AutonomyOptions o) {
  const double down = -o.fov.v_min_deg * M_PI / 180.0;
  if (down <= 0.01) return o;
  const double blind = o.fov.mount_height_m / std::tan(down) + 0.5;
  o.params.map.seed_search_radius_m = std::max(o.params.map.seed_search_radius_m, blind);
  o.params.graph.root_radius_m = std::max(o.params.graph.root_radius_m, 2.0 * blind);
  return o;
}

ControlGains gains_of(const config::SafetyConfig& s) {
  ControlGains g;
  g.on_reference_full_m = s.turn_on_reference_full_m;
  g.on_reference_zero_m = s.turn_on_reference_zero_m;
  return g;
}

core::plan::BodyPose pose_on(const core::plan::BsplineTrajectory& t, double tau) {
  return t.pose(std::clamp(tau, t.t_start(), t.t_end()));
}
}  // namespace

Autonomy::Autonomy(Platform& platform, const rt::Clock& clock, AutonomyOptions options)
    : platform_(platform),
      clock_(clock),
      opt_(widen_for_blind_zone(std::move(options))),
      trace_(opt_.trace_events),
      pool_(opt_.scan_pool),
      filled_q_(opt_.scan_pool),
      free_q_(opt_.scan_pool),
      map_(opt_.params.map, opt_.params.robot),
      graph_(opt_.params.graph),
      frontiers_(opt_.params.graph),
      clusters_(opt_.params.graph),
      viewpoints_(opt_.params.graph, opt_.fov),
      rng_(opt_.seed),
      policy_(make_exploration_policy(opt_.method, opt_.params)),
      plan_q_(64),
      law_(opt_.params.robot, gains_of(opt_.params.safety)),
      safety_(opt_.params.safety),
      lookahead_(opt_.params.robot, opt_.params.map.voxel_size_m),
      stop_q_(256) {
  for (ScanBuffer& b : pool_) {
    b.points_m.reserve(opt_.scan_reserve_points);
    free_q_.try_push(&b);
  }
  drop_buf_.points_m.reserve(opt_.scan_reserve_points);
  // ControlLaw::turn_poses / slide_poses: no allocation in the control task.
  turn_poses_.reserve(ControlLaw::max_swept_poses());
  if (!policy_->local_layer())
    idle_local_ = std::make_unique<core::plan::LocalPlanner>(opt_.params.robot, opt_.params.plan,
                                                             opt_.params.map.voxel_size_m);
  rt::SchedulerOptions so;
  so.trace = &trace_;
  so.lockstep_event_hz = opt_.lockstep_event_hz;
  so.use_priorities = opt_.params.realtime.sched_fifo;
  so.pin_cpus = opt_.params.realtime.cpu_pinning;
  so.lock_memory = opt_.params.realtime.mlockall;
  const std::vector<rt::TaskSpec> table = task_table();
  sched_ = std::make_unique<rt::Scheduler>(table, so);
}

Autonomy::~Autonomy() {
  if (sched_ && sched_->running()) sched_->stop();
}

// ---------------------------------------------------------------------------------------------
// THE task table (ArduPilot style): every periodic activity of the firmware, in one place.
// Rates, budgets, priorities and CPUs come from the configuration's `rates` section.
// Order matters in lockstep (ties run in table order): ingest delivers before the map consumes,
// the map publishes before the planner reads, the planner before the control task tracks.
std::vector<rt::TaskSpec> Autonomy::task_table() {
  const config::RateTable& r = opt_.params.rates;
  auto row = [](const char* name, const config::TaskRate& tr, std::function<void()> fn) {
    return rt::TaskSpec{name, tr.rate_hz, tr.budget_us, tr.priority, tr.cpu, std::move(fn), -1};
  };
  std::vector<rt::TaskSpec> table = {
      //  name         rate/budget/prio/cpu   body
      row(kTaskNames[kIngest], r.ingest, [this] { ingest_step(); }),        // event-driven (polled)
      row(kTaskNames[kMap], r.map, [this] { map_step(); }),                 // 10 Hz
      row(kTaskNames[kPlan], r.plan, [this] { plan_step(); }),              // 2 Hz
      row(kTaskNames[kControl], r.control, [this] { control_step(); }),     // 50 Hz
      row(kTaskNames[kWatchdog], r.watchdog, [this] { watchdog_step(); }),  // 10 Hz
      row(kTaskNames[kTelemetry], r.telemetry, [this] { telemetry_step(); }),  // 1 Hz
  };
  table[kIngest].fd = opt_.ingest_fd;  // real time: runs when the LiDAR socket is readable
  return table;
}

bool Autonomy::suspend_task(const char* name, bool on) {
  for (int i = 0; i < kTaskCount; ++i)
    if (std::strcmp(name, kTaskNames[i]) == 0) {
      suspended_[i].store(on, std::memory_order_release);
      return true;
    }
  return false;
}

ExplorationStatus Autonomy::status() const {
  ExplorationStatus s;
  status_mb_.read(s);
  return s;
}

VelocityCommand Autonomy::last_command() const {
  VelocityCommand c;
  cmd_mb_.read(c);
  return c;
}

void Autonomy::log(const std::string& line) const {
  if (opt_.log)
    opt_.log(line);
  else
    std::fprintf(stderr, "storey: %s\n", line.c_str());
}

// ---- ingest (event-driven): the platform's next sweep into a pool buffer, queued to the map.
void Autonomy::ingest_step() {
  if (suspended(kIngest)) return;
  for (;;) {
    if (!ingest_buf_ && !free_q_.try_pop(ingest_buf_)) ingest_buf_ = nullptr;
    ScanBuffer& dst = ingest_buf_ ? *ingest_buf_ : drop_buf_;
    if (!platform_.take_scan(dst)) return;
    scan_stamp_mb_.write(dst.stamp_s);
    if (!ingest_buf_) {  // the map task is behind: every buffer is in flight
      scans_dropped_.fetch_add(1, std::memory_order_relaxed);
      continue;
    }
    filled_q_.try_push(ingest_buf_);  // cannot fail: the pool has as many buffers as slots
    ingest_buf_ = nullptr;
  }
}

// ---- map + graph (10 Hz): insert scans, traversability, C_reach, G_real, frontiers, clusters,
// viewpoints; publish the world model.
void Autonomy::map_step() {
  if (suspended(kMap)) return;
  ScanBuffer* b = nullptr;
  while (filled_q_.try_pop(b)) {
    map_.insert_scan(b->origin_m, b->points_m);
    changed_.push_back(core::graph::scan_bounds(b->origin_m, b->points_m));
    ++scans_inserted_;
    free_q_.try_push(b);
  }
  PoseSample pose;
  if (pose_mb_.read(pose) == 0) return;  // no odometry yet: C_reach needs the robot's foot
  const Eigen::Vector3f foot = pose.position().cast<float>();
  level_.update(foot);
  // The plan task saw a blind climb end on its landing (LocalPlanner::landings()).
  const bool landed = landed_request_.exchange(false, std::memory_order_acq_rel);
  if (!startup_support_done_ && scans_inserted_ > 0) {
    startup_support_done_ = true;
    startup_points_ = insert_startup_support(foot);
  } else if (opt_.params.plan.climb_blind && scans_inserted_ > 0 &&
             (opt_.params.plan.flight_foot
                  ? (level_.level() || landed) &&
                        ((foot - last_support_foot_).norm() > 1.0f ||
                         std::abs(foot.z() - last_support_foot_.z()) > LevelTracker::kTolM)
                  : (foot - last_support_foot_).norm() > 1.0f) &&
             support_fraction(map_.view(), foot) < 0.5f) {
    // Stepped onto ground the LiDAR has not seen (a landing reached blind from a flight, whose
    // pitch kept the LiDAR looking over it): the legs stand on it, enter it as well. Once per
    // metre; with plan.flight_foot on every new level too, but only where the robot walks level
    // or a climb has just ended on its landing: entered on the top tread, the landing 0.94 m on
    // and a step up was not (house seed 8, session 16: no node grew on the upper floor,
    // "complete" with it at 10 %); entered on the top tread while climbing, the disc laid the
    // landing 0.17 m low (test_stair seed 2, session 17: every trajectory onto it pitched the
    // body into the railing). A climb ends as little as 0.07 m past the top riser (house seed 4),
    // and a robot stopped mid-flight stands as still as one on its landing (office seed 2: a disc
    // at z 1.0 over the treads, the flight never found again).
    insert_startup_support(foot);
  }
  map_.update_traversability();
  map_.update_reachable(foot);
  const core::map::MapView view = map_.view();
  // Until G_real has a node near the robot, anchor it at the latest C_reach seed: the ground
  // under the feet is in the LiDAR's blind ring, the seed is the nearest observed support.
  Eigen::Vector3f anchor = foot;
  if (graph_.node_count() == 0 && !map_.reach_roots().empty()) {
    const core::map::VoxelKey k = map_.reach_roots().back();
    anchor = view.centre_of(k);
    if (const auto h = view.surface_height_m(k)) anchor.z() = *h;
  }
  graph_.update(view, anchor, changed_, rng_);
  const core::graph::FrontierUpdateStats fs = frontiers_.update(graph_, view, foot, changed_);
  const auto& clusters = clusters_.update(graph_);
  const auto& vps = viewpoints_.update(graph_, view, clusters);
  ++map_cycle_;
  // Changed regions travel with the world model until the plan task has consumed them.
  const uint64_t seen = plan_seen_cycle_.load(std::memory_order_acquire);
  std::erase_if(pending_changes_, [seen](const auto& c) { return c.first <= seen; });
  for (const core::graph::Aabb& b : changed_)
    if (!b.empty()) pending_changes_.push_back({map_cycle_, b});
  changed_.clear();

  // Publication allocates (an immutable copy is the price of lock-free readers); the old
  // versions are released by the telemetry task (Snapshot::collect), not here.
  auto w = std::make_shared<WorldModel>();
  w->cycle = map_cycle_;
  w->stamp_s = now_s();
  w->map = map_.snapshot();
  w->graph = graph_;
  w->clusters = clusters;
  w->viewpoints = vps;
  w->settled = graph_.idle() && frontiers_.idle();
  w->frontier_nodes = fs.frontiers;
  w->scans = scans_inserted_;
  w->changes = pending_changes_;
  world_.publish(std::shared_ptr<const WorldModel>(std::move(w)));
}

// Start-up support (once, and with plan.climb_blind on unseen ground): blind_support.hpp. The
// radius is capped at the blind radius + 0.3 m.
size_t Autonomy::insert_startup_support(const Eigen::Vector3f& foot) {
  last_support_foot_ = foot;
  const double down = -opt_.fov.v_min_deg * M_PI / 180.0;
  if (down <= 0.01 || opt_.startup_support_radius_m <= 0) return 0;
  const double r =
      std::min(opt_.startup_support_radius_m, opt_.fov.mount_height_m / std::tan(down) + 0.3);
  const std::vector<Eigen::Vector3f> pts =
      blind_support_points(map_.view(), foot, opt_.fov.mount_height_m, r);
  const Eigen::Vector3f origin = foot + Eigen::Vector3f(0, 0, float(opt_.fov.mount_height_m));
  map_.insert_scan(origin, pts);
  changed_.push_back(core::graph::scan_bounds(origin, pts));
  return pts.size();
}

// ---- plan (2 Hz): the exploration policy (the paper's ExplorationPlanner or a baseline) on the
// latest world model; publishes its trajectory, holds, or ends the run.
void Autonomy::plan_step() {
  if (suspended(kPlan)) return;
  const double now = now_s();
  plan_alive_mb_.write(now);  // the planner vouches for its latest trajectory
  const auto wv = world_.read();
  PoseSample pose;
  if (!wv.ptr || pose_mb_.read(pose) == 0) return;
  const WorldModel& w = *wv.ptr;
  ++plan_cycles_;
  if (replan_request_.exchange(false, std::memory_order_acq_rel)) policy_->drop_target();

  // Regions changed since the previous call: every box of the map cycles after the last world
  // model this task consumed (the map task keeps them until acknowledged).
  plan_changes_.clear();
  for (const auto& [cycle, box] : w.changes)
    if (cycle > plan_last_cycle_) plan_changes_.push_back(box);
  plan_last_cycle_ = w.cycle;
  plan_seen_cycle_.store(w.cycle, std::memory_order_release);

  const core::map::MapView view = w.map->view();
  core::plan::ExplorationInput in;
  in.view = &view;
  in.map_version = w.map->version();
  in.graph = &w.graph;
  in.clusters = &w.clusters;
  in.viewpoints = &w.viewpoints;
  in.robot_foot_m = pose.position();
  in.robot_yaw_rad = pose.yaw_rad;
  in.robot_velocity_mps = pose.velocity_world();
  in.t_s = now;
  // The lag of the trajectory followed, if it is the one last published.
  if (TrajectoryProgress pr;
      opt_.params.plan.reference_clock && progress_mb_.read(pr) != 0 && pr.id == traj_id_)
    in.trajectory_lag_s = pr.lag_s;
  in.changed_regions = &plan_changes_;
  core::plan::ExplorationResult r = policy_->plan(in);
  if (const core::plan::LocalPlanner* l = policy_->local_layer();
      l && l->landings() != landings_seen_) {
    landings_seen_ = l->landings();
    landed_request_.store(true, std::memory_order_release);
  }

  using PS = core::plan::ExplorationStatus;
  auto publish = [&](std::shared_ptr<PlannedTrajectory> p) {
    p->id = ++traj_id_;
    p->stamp_s = now;
    traj_.publish(std::shared_ptr<const PlannedTrajectory>(std::move(p)));
  };
  auto hold = [&] {  // an empty trajectory: the control task holds still
    const auto cur = traj_.read();
    if (cur.ptr && !cur.ptr->trajectory.empty()) publish(std::make_shared<PlannedTrajectory>());
  };
  ExplorationStatus s;
  s.nodes = uint32_t(w.graph.node_count());  // before the switch: stranded() reads it
  if (r.floor_changed && r.floor >= 0)
    plan_q_.try_push(PlanEvent{PlanEvent::kFloor, now, r.floor, r.reference_floor, r.dz_m, "",
                               float(pose.x_m), float(pose.y_m), float(pose.z_m)});
  if (r.prior_built)
    plan_q_.try_push(PlanEvent{PlanEvent::kPrior, now, r.floor, r.reference_floor, r.dz_m, ""});
  if (r.status != PS::kFailed) last_failure_ = nullptr;
  switch (r.status) {
    case PS::kNewTrajectory: {
      auto p = std::make_shared<PlannedTrajectory>();
      p->trajectory = std::move(r.trajectory);
      // Drive only the real prefix (Sec. IV-C); never past the curve's end.
      p->real_until_s = std::min(r.real_until_s, p->trajectory.t_end());
      p->target_cluster = r.target_cluster;
      p->target_m = r.target_m;
      publish(std::move(p));
      ++trajectories_;
      if (opt_.plan_log) {
        PlanEvent e{PlanEvent::kTrajectory, now, r.floor, -1, 0, r.reason};
        e.x_m = float(r.target_m.x());
        e.y_m = float(r.target_m.y());
        e.z_m = float(r.target_m.z());
        e.cluster = r.target_cluster;
        plan_q_.try_push(e);
      }
      idle_since_s_ = -1;
      complete_ = false;
      break;
    }
    case PS::kKeep:
      idle_since_s_ = -1;
      complete_ = false;
      break;
    case PS::kExploring:
      // No target this cycle while the map grows: the control task finishes (or holds the end
      // of) the current trajectory, as before a target exists. Not idle: completion needs the
      // policy itself to say so.
      idle_since_s_ = -1;
      break;
    case PS::kFailed:
      hold();
      idle_since_s_ = -1;
      if (r.reason != last_failure_)  // once per distinct reason, not every cycle
        plan_q_.try_push(PlanEvent{PlanEvent::kFailed, now, r.floor, -1, 0, r.reason});
      last_failure_ = r.reason;
      break;
    case PS::kComplete: {
      hold();
      if (idle_since_s_ < 0) idle_since_s_ = now;
      // A one-cycle kComplete while the map still grows must not end the run: every cluster
      // must be set aside by the local layer or unreachable through G_real (not merely failed
      // once in Stage 3 this cycle), and then the graph must have settled for
      // complete_after_s, or the exhausted state must have lasted complete_unsettled_after_s
      // (the graph's bounded per-cycle work can churn on sensor noise without ever yielding a
      // reachable target).
      // (A baseline keeps its own frontiers and set-aside list: its kComplete is exhaustion.)
      count_exhausted(w, s);
      const bool exhausted = !policy_->local_layer() ||
                             s.clusters_set_aside + s.clusters_unreachable >= w.clusters.size();
      if (!exhausted) idle_since_s_ = now;
      const double idle_s = now - idle_since_s_;
      const bool was_complete = complete_;
      if (w.graph.node_count() > 0 && ((w.settled && idle_s >= opt_.complete_after_s) ||
                                       idle_s >= opt_.complete_unsettled_after_s))
        complete_ = true;
      // Frontiers left that no real edge joins to a robot cut off in a small part of the graph:
      // not a building explored (teaching_building seed 1, session 31: 293 of 300 clusters
      // unreachable from a 3-node component on a phantom floor).
      stranded_ = complete_ && stranded(s);
      if (complete_ && !was_complete)
        plan_q_.try_push(PlanEvent{stranded_ ? PlanEvent::kStranded : PlanEvent::kComplete, now,
                                   r.floor, -1, 0, r.reason});
      break;
    }
  }

  s.stamp_s = now;
  s.state = !complete_  ? ExplorationState::kExploring
            : stranded_ ? ExplorationState::kStranded
                        : ExplorationState::kComplete;
  s.method = policy_->name();
  s.last_plan = r.status;
  s.plan_reason = r.reason;
  s.edges = uint32_t(w.graph.edge_count());
  s.frontier_nodes = w.frontier_nodes;
  s.clusters = uint32_t(w.clusters.size());
  if (const auto* g = policy_->goals_set_aside()) {
    s.goals_stood_at = int32_t(g->stood_at);
    s.goals_overdue = int32_t(g->overdue);
    s.goals_no_trajectory = int32_t(g->no_trajectory);
    s.goals_no_progress = int32_t(g->no_progress);
  }
  s.trajectories = trajectories_;
  s.plan_cycles = plan_cycles_;
  if (const auto cur = traj_.read(); cur.ptr && !cur.ptr->trajectory.empty()) {
    s.has_target = true;
    s.target_cluster = cur.ptr->target_cluster;
    s.target_x_m = float(cur.ptr->target_m.x());
    s.target_y_m = float(cur.ptr->target_m.y());
    s.target_z_m = float(cur.ptr->target_m.z());
  }
  s.floor_hint = int(std::lround(pose.z_m / opt_.params.graph.floor_height_hint_m));
  s.floor = r.floor;
  s.guided = r.guided;
  s.zones_deferred = uint32_t(std::max(0, r.zones_deferred));
  if (const core::plan::ExplorationPlanner* macro = policy_->macro_layer()) {
    s.floors_known = uint32_t(macro->floors().floors().size());
    const core::plan::HybridGraph& h = macro->hybrid();
    s.prior = h.has_prior();
    if (s.prior) {
      s.zones = uint32_t(h.zones().size());
      for (const core::plan::HybridZone& z : h.zones())
        s.zones_left += z.state != core::plan::ZoneState::kCompleted;
    }
    if (r.prior_built) prior_dz_m_ = r.dz_m, prior_reference_ = r.reference_floor;
    s.prior_dz_m = prior_dz_m_;
    s.reference_floor = s.prior ? prior_reference_ : -1;
  }
  status_mb_.write(s);
}

// Clusters the local layer has set aside entirely, and clusters with no node connected to the
// robot's node through real (confirmed or tentative) edges: the two ways a frontier cluster left
// on the map is exhausted (LocalPlanner Stage 1 counts them the same way).
void Autonomy::count_exhausted(const WorldModel& w, ExplorationStatus& s) {
  const core::graph::ReachableGraph& g = w.graph;
  const core::plan::LocalPlanner& local = planner_for_record();
  std::vector<uint32_t>& parent = uf_scratch_;
  parent.resize(g.node_capacity());
  for (uint32_t i = 0; i < parent.size(); ++i) parent[i] = i;
  auto find = [&](uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  for (size_t e = 0; e < g.edge_capacity(); ++e) {
    const core::graph::GraphEdge& ge = g.edge(core::graph::EdgeId(e));
    if (!ge.alive || ge.state == core::graph::ElementState::kHypothetical) continue;
    parent[find(ge.a)] = find(ge.b);
  }
  const bool rooted = g.root() != core::graph::kNoId && g.root() < parent.size();
  const uint32_t root = rooted ? find(g.root()) : 0;
  if (rooted)
    for (uint32_t i = 0; i < parent.size(); ++i)
      s.robot_component_nodes += g.node(core::graph::NodeId(i)).alive && find(i) == root;
  for (const core::graph::FrontierCluster& c : w.clusters) {
    bool open = false, connected = false;
    for (core::graph::NodeId n : c.nodes) {
      if (local.ignored(g.node(n).p_m)) continue;
      open = true;
      connected = connected || (rooted && find(n) == root);
    }
    if (!open)
      ++s.clusters_set_aside;
    else if (!connected)
      ++s.clusters_unreachable;
  }
}

// ---- control (50 Hz): odometry in, tracking, FCL look-ahead, safety, command out.
void Autonomy::control_step() {
  if (suspended(kControl)) return;
  const double now = now_s();
  const double dt = 1.0 / opt_.params.rates.control.rate_hz;
  PoseSample pose;
  if (platform_.latest_pose(pose)) {
    // A pose that did not advance is not fresh: pose_stale uses the sample's own stamp.
    last_pose_ = pose;
    pose_mb_.write(pose);
  }
  const LinkHealth link = platform_.link();

  // Trajectory: a new one starts at the point nearest the robot within its first seconds
  // (ControlLaw::entry_time). With plan.brake_start a moving robot first brakes on the trajectory
  // it follows (the planner started the new one where that ends): braking straight off a curve
  // while turning onto the new one swept the body into what the curve went round (house seed 3's
  // railing, session 16).
  const auto enter = [&](std::shared_ptr<const PlannedTrajectory> next) {
    ctl_traj_ = std::move(next);
    pending_.reset();
    brake_k_ = 1.0;
    entering_ = true;
    hold_turn_ = false;
    if (ctl_traj_ && !ctl_traj_->trajectory.empty())
      tau_ = ControlLaw::entry_time(ctl_traj_->trajectory,
                                    Eigen::Vector2d(last_pose_.x_m, last_pose_.y_m));
    entry_tau_ = tau_;
    lag_s_ = std::max(0.0, now - tau_);  // entered late (braking first, the plan's latency)
  };
  const auto tv = traj_.read();
  if (tv.version != ctl_traj_version_) {
    ctl_traj_version_ = tv.version;
    const Eigen::Vector2d v = last_pose_.velocity_world();
    // Only a trajectory the planner started where the braking ends: one starting on the old one
    // (followed, or already braked on) ahead of the robot (a climb or a descent starts where the
    // robot stood).
    bool starts_ahead = false;
    if (opt_.params.plan.brake_start && tv.ptr && !tv.ptr->trajectory.empty() && ctl_traj_ &&
        !ctl_traj_->trajectory.empty()) {
      const auto& old_t = ctl_traj_->trajectory;
      const bool on_old = tau_ < std::min(old_t.t_end(), ctl_traj_->real_until_s) &&
                          (old_t.sample(tau_).p_m - last_pose_.position()).head<2>().norm() < 0.3;
      const Eigen::Vector3d p0 = tv.ptr->trajectory.sample(tv.ptr->trajectory.t_start()).p_m;
      for (double s = tau_ + 0.1;
           (on_old || pending_) && s <= std::min(old_t.t_end(), tau_ + 2.5) && !starts_ahead;
           s += 0.05)
        starts_ahead = (old_t.sample(s).p_m - p0).head<2>().norm() < 0.1;
    }
    const bool brake_any = opt_.params.plan.enter_at_rest && tv.ptr &&
                           !tv.ptr->trajectory.empty() && ctl_traj_ &&
                           !ctl_traj_->trajectory.empty();
    if ((starts_ahead || brake_any) && v.norm() > 0.2 && law_.turns_away(tv.ptr->trajectory, v)) {
      if (!pending_) brake_k_ = 1.0, brake_v0_ = v.norm();
      pending_ = tv.ptr;
    } else {
      enter(tv.ptr);
    }
  }
  if (pending_) {
    brake_k_ = std::max(0.0, brake_k_ - opt_.params.robot.max_accel_mps2 * dt / brake_v0_);
    if (brake_k_ <= 0.0 || std::hypot(last_pose_.vx_mps, last_pose_.vy_mps) < 0.05) enter(pending_);
  }
  const bool has_traj = ctl_traj_ && !ctl_traj_->trajectory.empty();
  const double tau_end =
      has_traj ? std::min(ctl_traj_->trajectory.t_end(), ctl_traj_->real_until_s) : 0;
  if (has_traj && !pending_ && tau_ < tau_end && opt_.params.plan.reference_catch_up) {
    const double s = ControlLaw::catch_up_time(ctl_traj_->trajectory, tau_, tau_end,
                                               Eigen::Vector2d(last_pose_.x_m, last_pose_.y_m));
    lag_s_ = std::max(0.0, lag_s_ - (s - tau_));
    tau_ = s;
  }
  core::plan::TrajectorySample ref;
  double err = 0, speed_k = 1.0;
  if (has_traj) {
    ref = ctl_traj_->trajectory.sample(std::min(tau_, tau_end));
    if (tau_ >= tau_end) ref.v_mps.setZero(), ref.yaw_rate_rps = 0;  // hold the end pose
    ref.v_mps *= brake_k_, ref.yaw_rate_rps *= brake_k_;             // braking on it: slower
    speed_k = ControlLaw::speed_rate(ref.v_mps.head<2>(), last_pose_.velocity_world(),
                                     opt_.params.safety.reference_speed_lead_mps);
    ref.v_mps *= speed_k, ref.yaw_rate_rps *= speed_k;  // no faster than the robot can follow
    err = (ref.p_m - last_pose_.position()).head<2>().norm();
  }
  const bool following = has_traj && (tau_ < tau_end || err > 0.15);

  // FCL look-ahead over the next lookahead_s of the trajectory, on the latest map: re-checked
  // whenever the map or the trajectory changes (between changes the answer can only shift
  // along the curve; the extra 0.2 s covers the 10 Hz map period). With
  // safety.lookahead_on_plan_grid the poses are those of the planner's checks (check_on_grid), so
  // both agree on the same map, and every new trajectory predicted to collide asks for a replan.
  const auto wv = world_.read();
  if (has_traj && wv.ptr &&
      (wv.version != ctl_checked_map_ || ctl_traj_version_ != ctl_checked_traj_)) {
    const bool new_traj = ctl_traj_version_ != ctl_checked_traj_;
    ctl_checked_map_ = wv.version;
    ctl_checked_traj_ = ctl_traj_version_;
    const auto& t = ctl_traj_->trajectory;
    const double horizon =
        std::max(0.0, std::min(opt_.params.safety.lookahead_s + 0.2, tau_end - tau_));
    const core::map::MapView view = wv.ptr->map->view();
    const auto pose_at = [&](double s) { return pose_on(t, s); };
    const bool on_grid = opt_.params.safety.lookahead_on_plan_grid;
    core::plan::CollisionHit hit =
        on_grid ? lookahead_.check_on_grid(view, pose_at, t.t_start(), t.t_end(), tau_, horizon)
                : lookahead_.check_ahead(view, pose_at, tau_, horizon, 0.0);
    // safety.check_body_turn: the body's own turn towards the reference, where the body is. A
    // body whose own pose already overlaps (its margin at a jamb seen late) is not stopped for
    // it: the planner starts from the nearest clear pose (LocalPlanner::free_start). A turn that
    // would collide is first held while the body slides onto its reference, if that and the
    // turn there are clear (ControlLaw::slide_poses); only then stop and replan (a stop asks
    // for a new plan, which drops the target: at the teaching building's U-stair every trip
    // up the flight was used up so, session 41).
    hold_turn_ = false;
    if (!hit.collides && opt_.params.safety.check_body_turn && following) {
      law_.turn_poses(ref, last_pose_, turn_poses_);
      if (!turn_poses_.empty()) {
        const core::plan::BodyPose here{last_pose_.position(), last_pose_.yaw_rad, 0.0, now};
        if (!lookahead_.check_poses(view, std::span(&here, 1)).collides)
          hit = lookahead_.check_poses(view, turn_poses_);
        if (hit.collides) {
          law_.slide_poses(ref, last_pose_, turn_poses_);
          if (!turn_poses_.empty() && !lookahead_.check_poses(view, turn_poses_).collides)
            hit = core::plan::CollisionHit{}, hold_turn_ = true;
        }
      }
    }
    if (hit.collides && (!collision_predicted_ || (on_grid && new_traj)))
      replan_request_.store(true, std::memory_order_release);
    collision_predicted_ = hit.collides;
  } else if (!has_traj) {
    collision_predicted_ = false;
  }

  SafetyInputs in;
  in.now_s = now;
  double scan_s = -1, vouched_s = -1;
  if (scan_stamp_mb_.read(scan_s) == 0) scan_s = -1;
  if (plan_alive_mb_.read(vouched_s) == 0) vouched_s = -1;
  in.last_scan_s = scan_s;
  in.pose_stamp_s = last_pose_.stamp_s;
  in.following = following;
  in.trajectory_vouched_s =
      has_traj || vouched_s < 0 ? vouched_s : now;  // idle: nothing to vouch for
  in.link_connected = link.connected;
  in.link_last_state_s = link.last_state_s;
  in.collision_predicted = collision_predicted_;
  in.operator_stop = operator_stop_.load(std::memory_order_acquire);
  in.overruns = overrun_flag_.load(std::memory_order_acquire);
  const SafetyDecision d = safety_.evaluate(in);
  for (int r = 0; r < int(StopReason::kCount); ++r) {
    if (d.raised & (1u << r)) {
      reason_events_[r].fetch_add(1, std::memory_order_release);
      stop_q_.try_push(StopEvent{now, StopReason(r), true});
    }
    if (d.cleared & (1u << r)) stop_q_.try_push(StopEvent{now, StopReason(r), false});
  }
  if (d.new_stop) safety_stops_.fetch_add(1, std::memory_order_release);
  stop_mask_.store(d.mask, std::memory_order_release);

  VelocityCommand cmd;
  if (!d.stop && following) {
    double yaw_scale = 1.0;
    if (entering_ && opt_.params.safety.turn_on_reference) {
      yaw_scale = law_.yaw_gate(ctl_traj_->trajectory, entry_tau_, std::min(tau_, tau_end), ref,
                                last_pose_);
      entering_ = yaw_scale < 1.0;
    }
    hold_turn_ = hold_turn_ && err > ControlLaw::kSlideStepM;  // on it: the turn was checked
    cmd = law_.track(ref, last_pose_, prev_cmd_, dt, hold_turn_ ? 0.0 : yaw_scale);
    // Progress along the curve only while tracking well: after a stop or a lag the reference
    // waits for the robot instead of running away from it.
    const double rate = ControlLaw::progress_rate(err, wrap_angle(ref.yaw_rad - last_pose_.yaw_rad),
                                                  opt_.params.safety.reference_yaw_gate_rad);
    if (tau_ < tau_end) lag_s_ += dt * (1.0 - rate * brake_k_ * speed_k);
    tau_ = std::min(tau_ + dt * rate * brake_k_ * speed_k, tau_end);
  } else if (has_traj && tau_ < tau_end) {
    lag_s_ += dt;  // stopped: the reference waits
  }
  progress_mb_.write(TrajectoryProgress{has_traj ? ctl_traj_->id : 0, lag_s_, tau_});
  // else: zero command (a stop is commanded in this very period; the robot's own deceleration
  // limits bring it to rest).
  cmd.stamp_s = now;
  platform_.send_command(cmd);
  cmd_mb_.write(cmd);
  prev_cmd_ = cmd;
}

// ---- watchdog (10 Hz): control-task budget overruns within the last window.
void Autonomy::watchdog_step() {
  if (suspended(kWatchdog)) return;
  const uint64_t ov = sched_->stats(kControl).overruns.load(std::memory_order_relaxed);
  const uint64_t recent = ov - wd_overruns_;
  wd_overruns_ = ov;
  const bool flag = opt_.stop_on_overruns && int64_t(recent) > opt_.params.safety.max_overruns;
  overrun_flag_.store(flag, std::memory_order_release);
}

// ---- telemetry (1 Hz, non-RT): the stop log, release of old snapshots.
void Autonomy::telemetry_step() {
  if (suspended(kTelemetry)) return;
  StopEvent e;
  char line[256];
  while (stop_q_.try_pop(e)) {
    std::snprintf(line, sizeof line, "t=%.2f s: safety stop %s: %s", e.t_s,
                  e.raised ? "raised" : "cleared", to_string(e.reason));
    log(line);
  }
  PlanEvent p;
  while (plan_q_.try_pop(p)) {
    switch (p.kind) {
      case PlanEvent::kFloor:
        std::snprintf(line, sizeof line, "t=%.2f s: on floor %d (robot at %.2f, %.2f, %.2f m)",
                      p.t_s, p.floor, double(p.x_m), double(p.y_m), double(p.z_m));
        break;
      case PlanEvent::kPrior:
        std::snprintf(line, sizeof line,
                      "t=%.2f s: prior built for floor %d from floor %d (dz %.2f m)", p.t_s,
                      p.floor, p.reference_floor, p.dz_m);
        break;
      case PlanEvent::kFailed:
        std::snprintf(line, sizeof line, "t=%.2f s: planner failed: %s", p.t_s, p.reason);
        break;
      case PlanEvent::kComplete:
        std::snprintf(line, sizeof line, "t=%.2f s: exploration complete: %s", p.t_s, p.reason);
        break;
      case PlanEvent::kStranded:
        std::snprintf(line, sizeof line,
                      "t=%.2f s: stranded: %s, but the robot is cut off from the frontiers left",
                      p.t_s, p.reason);
        break;
      case PlanEvent::kTrajectory: {  // plan.csv only, not the log
        if (!opt_.plan_log) continue;
        std::string reason = p.reason;  // CSV: commas in a reason become semicolons
        std::replace(reason.begin(), reason.end(), ',', ';');
        std::snprintf(line, sizeof line, "%.2f,%s,%d,%.2f,%.2f,%.2f", p.t_s, reason.c_str(),
                      p.cluster, double(p.x_m), double(p.y_m), double(p.z_m));
        opt_.plan_log(line);
        continue;
      }
    }
    log(line);
  }
  world_.collect();
  traj_.collect();
}

}  // namespace storey::firmware
