#include "config/parameters.hpp"

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <set>
#include <sstream>

namespace storey::config {

namespace fs = std::filesystem;

namespace {

// ---- string checks ------------------------------------------------------------------------

std::string check_ipv4(const std::string& s) {
  int parts = 0;
  std::size_t i = 0;
  while (i <= s.size()) {
    std::size_t j = s.find('.', i);
    if (j == std::string::npos) j = s.size();
    const std::string part = s.substr(i, j - i);
    if (part.empty() || part.size() > 3 ||
        part.find_first_not_of("0123456789") != std::string::npos || std::stoi(part) > 255) {
      return "'" + s + "' is not an IPv4 address (a.b.c.d)";
    }
    ++parts;
    i = j + 1;
  }
  return parts == 4 ? "" : "'" + s + "' is not an IPv4 address (a.b.c.d)";
}

std::string check_ipv4_or_empty(const std::string& s) {
  return s.empty() ? "" : check_ipv4(s);
}

// Linux interface names: 1..15 characters (IFNAMSIZ - 1), no '/', no whitespace.
std::string check_ifname(const std::string& s) {
  if (s.size() > 15 || s.find_first_of("/ \t:") != std::string::npos) {
    return "'" + s +
           "' is not a network interface name (at most 15 characters, no '/', ':' "
           "or spaces)";
  }
  return "";
}

std::string check_ifname_nonempty(const std::string& s) {
  return s.empty() ? "must name a network interface" : check_ifname(s);
}

// ---- the schema: one function per section -------------------------------------------------
// Key names are the struct field names; angles are read in degrees (suffix _deg).

constexpr Range kPort{1, 65535};
constexpr Range kNonNegWeight{0.0, 100.0};

void read_robot(SectionReader&& r, core::RobotModel& o) {
  r.get("body_length_m", o.body_length_m, Range{0.1, 3.0});
  r.get("body_width_m", o.body_width_m, Range{0.1, 2.0});
  r.get("body_height_m", o.body_height_m, Range{0.05, 2.0});
  r.get("body_margin_m", o.body_margin_m, Range{0.0, 0.5});
  r.get("step_height_m", o.step_height_m, Range{0.0, 0.5});
  r.get_deg("max_slope_deg", o.max_slope_rad, Range{0.0, 60.0});
  r.get("max_speed_mps", o.max_speed_mps, Range{0.05, 5.0});
  r.get("max_yaw_rate_rps", o.max_yaw_rate_rps, Range{0.05, 6.0});
  r.get("max_accel_mps2", o.max_accel_mps2, Range{0.05, 10.0});
  r.get("max_yaw_accel_rps2", o.max_yaw_accel_rps2, Range{0.05, 20.0});
}

void read_map(SectionReader&& r, core::map::MapOptions& o) {
  r.get("voxel_size_m", o.voxel_size_m, Range{0.01, 1.0});
  r.get("max_range_m", o.max_range_m, Range{0.5, 300.0});
  r.get("min_range_m", o.min_range_m, Range{0.0, 10.0});
  r.get("log_odds_hit", o.log_odds_hit, Range{0.01, 10.0});
  r.get("log_odds_miss", o.log_odds_miss, Range{-10.0, -0.01});
  r.get("log_odds_min", o.log_odds_min, Range{-20.0, 0.0});
  r.get("log_odds_max", o.log_odds_max, Range{0.0, 20.0});
  r.get("log_odds_occupied", o.log_odds_occupied, Range{-10.0, 10.0});
  r.get("n_min", o.n_min, Range{1, 1000});
  r.get("spill_is_surface", o.spill_is_surface);
  r.get("miss_needs_crossing", o.miss_needs_crossing);
  r.get("floor_seen_from_above", o.floor_seen_from_above);
  r.get("neighbourhood_radius_m", o.neighbourhood_radius_m, Range{0.01, 5.0});
  r.get("neighbourhood_dz_m", o.neighbourhood_dz_m, Range{0.0, 2.0});
  r.get("n_ref", o.n_ref, Range{1, 100000});
  r.get("w_s", o.w_s, kNonNegWeight);
  r.get("w_r", o.w_r, kNonNegWeight);
  r.get("w_u", o.w_u, kNonNegWeight);
  r.get("tau_c", o.tau_c, Range{0.0, 100.0});
  r.get("fall_support_ratio", o.fall_support_ratio, Range{0.0, 1.0});
  r.get("collision_radius_m", o.collision_radius_m, Range{0.0, 2.0});
  r.get("seed_search_radius_m", o.seed_search_radius_m, Range{0.0, 10.0});
  r.get("world_limit_m", o.world_limit_m, Range{10.0, 1e7});
  r.get("ray_early_stop_voxels", o.ray_early_stop_voxels, Range{0, 100000});
}

void read_graph(SectionReader&& r, core::graph::GraphOptions& o) {
  r.get("r_e_m", o.r_e_m, Range{0.1, 10.0});
  r.get("node_clearance_m", o.node_clearance_m, Range{0.01, 10.0});
  r.get("k_max", o.k_max, Range{1, 64});
  r.get_deg("alpha_min_deg", o.alpha_min_rad, Range{0.0, 180.0});
  r.get("expansion_samples", o.expansion_samples, Range{1, 1000});
  r.get("rho_min", o.rho_min, Range{0.0, 1.0});
  r.get("surface_radius_factor", o.surface_radius_factor, Range{0.1, 10.0});
  r.get("probes", o.probes, Range{1, 360});
  r.get("theta_min", o.theta_min, Range{1, 360});
  r.get("probe_length_m", o.probe_length_m, Range{0.1, 50.0});
  r.get("cluster_capacity", o.cluster_capacity, Range{1, 1000});
  r.get("viewpoints_per_cluster", o.viewpoints_per_cluster, Range{1, 64});
  r.get("viewpoint_radius_m", o.viewpoint_radius_m, Range{0.1, 50.0});
  r.get("use_tentative", o.use_tentative);
  r.get("use_c_sur", o.use_c_sur);
  r.get("use_c_exp", o.use_c_exp);
  r.get("boundary_frontiers", o.boundary_frontiers);
  r.get("close_probes_at_holes", o.close_probes_at_holes);
  r.get("close_probes_at_wall_faces", o.close_probes_at_wall_faces);
  r.get("passage_frontiers", o.passage_frontiers);
  r.get("ramp_frontiers", o.ramp_frontiers);
  r.get("keep_reachable_cut", o.keep_reachable_cut);
  r.get("relink_cuts", o.relink_cuts);
  r.get("relink_tries", o.relink_tries, Range{1, 1000});
  r.get("surface_seen_from_above", o.surface_seen_from_above);
  r.get("neighbour_radius_factor", o.neighbour_radius_factor, Range{1.0, 5.0});
  r.get_deg("max_edge_slope_deg", o.max_edge_slope_rad, Range{0.0, 75.0});
  r.get("max_gap_m", o.max_gap_m, Range{0.0, 5.0});
  r.get("surface_tolerance_m", o.surface_tolerance_m, Range{0.0, 0.5});
  r.get("root_radius_m", o.root_radius_m, Range{0.05, 10.0});
  r.get("prune_persistence_updates", o.prune_persistence_updates, Range{0, 100000});
  r.get("floor_height_hint_m", o.floor_height_hint_m, Range{1.0, 20.0});
  r.get("max_expansions_per_update", o.max_expansions_per_update, Range{1, 1000000});
  r.get("max_revalidations_per_update", o.max_revalidations_per_update, Range{1, 10000000});
  r.get("max_frontier_updates", o.max_frontier_updates, Range{1, 10000000});
  r.get("surface_samples", o.surface_samples, Range{1, 4096});
  r.get("probe_height_m", o.probe_height_m, Range{0.0, 3.0});
  r.get("probe_unknown_m", o.probe_unknown_m, Range{0.0, 10.0});
  r.get("boundary_radius_m", o.boundary_radius_m, Range{0.01, 10.0});
  r.get("viewpoint_target_height_m", o.viewpoint_target_height_m, Range{0.0, 3.0});
}

void read_plan(SectionReader&& r, core::plan::PlanOptions& o) {
  r.get("r_z_m", o.r_z_m, Range{0.5, 100.0});
  r.get("min_zone_nodes", o.min_zone_nodes, Range{1, 10000});
  r.get("zone_capacity", o.zone_capacity, Range{1, 100000});
  r.get("window_w", o.window_w, Range{1, 16});
  r.get("max_candidates_k", o.max_candidates_k, Range{1, 8});  // DESIGN §4: K <= 8
  r.get("lambda_psi", o.lambda_psi, kNonNegWeight);
  r.get("lambda_a", o.lambda_a, kNonNegWeight);
  r.get("guidance_zones", o.guidance_zones, Range{1, 100});
  r.get("guidance_near_m", o.guidance_near_m, Range{0.0, 1000.0});
  r.get("floor_change_dz_m", o.floor_change_dz_m, Range{0.3, 10.0});
  r.get("hyp_discard_observations", o.hyp_discard_observations, Range{1, 1000});
  r.get("hyp_promote_radius_m", o.hyp_promote_radius_m, Range{0.01, 10.0});
  r.get("tsp_exact_max_n", o.tsp_exact_max_n, Range{1, 16});
  r.get("tsp_max_clusters", o.tsp_max_clusters, Range{1, 1000});
  r.get("heading_via_viewpoint_yaw", o.heading_via_viewpoint_yaw);
  r.get("astar_max_expansions", o.astar_max_expansions, Range{100, 100000000});
  r.get("astar_reachable_only", o.astar_reachable_only);
  r.get("astar_cost_weight", o.astar_cost_weight, kNonNegWeight);
  r.get("astar_clearance_weight", o.astar_clearance_weight, kNonNegWeight);
  r.get("astar_goal_tolerance_m", o.astar_goal_tolerance_m, Range{0.0, 5.0});
  r.get("traj_control_spacing_m", o.traj_control_spacing_m, Range{0.05, 5.0});
  r.get("traj_max_repairs", o.traj_max_repairs, Range{0, 1000});
  r.get("traj_grade_corners", o.traj_grade_corners);
  r.get("traj_retime", o.traj_retime);
  r.get("traj_retime_yaw_share", o.traj_retime_yaw_share, Range{0.1, 1.0});
  r.get("lookahead_s", o.lookahead_s, Range{0.1, 10.0});
  r.get("floor_stable_s", o.floor_stable_s, Range{0.0, 60.0});
  r.get("floor_stable_band_m", o.floor_stable_band_m, Range{0.01, 1.0});
  r.get("floor_stable_travel_m", o.floor_stable_travel_m, Range{0.0, 20.0});
  r.get("floor_node_band_m", o.floor_node_band_m, Range{0.05, 5.0});
  r.get("zone_clearance_radius_m", o.zone_clearance_radius_m, Range{0.1, 50.0});
  r.get("hyp_height_window_m", o.hyp_height_window_m, Range{0.01, 5.0});
  r.get("hyp_check_radius_m", o.hyp_check_radius_m, Range{0.5, 1000.0});
  r.get("hyp_bridge_radius_m", o.hyp_bridge_radius_m, Range{0.1, 20.0});
  r.get("zone_merge_cross_edges", o.zone_merge_cross_edges, Range{1, 10000});
  r.get("zone_merge_distance_m", o.zone_merge_distance_m, Range{0.0, 100.0});
  r.get("zone_visit_radius_m", o.zone_visit_radius_m, Range{0.1, 50.0});
  r.get("use_prior", o.use_prior);
  r.get("climb_blind", o.climb_blind);
  r.get("target_momentum", o.target_momentum);
  r.get("path_retries", o.path_retries, Range{0, 10});
  r.get("arrive_along_path", o.arrive_along_path);
  r.get("face_cluster", o.face_cluster);
  r.get("floor_first", o.floor_first);
  r.get("reach_off_graph", o.reach_off_graph);
  r.get("keep_on_failed_replan", o.keep_on_failed_replan);
  r.get("keep_guided_target", o.keep_guided_target);
  r.get("climb_axis_ahead_m", o.climb_axis_ahead_m, Range{0.0, 1.5});
  r.get("flight_foot", o.flight_foot);
  r.get("brake_start", o.brake_start);
  r.get("reference_clock", o.reference_clock);
  r.get("reference_catch_up", o.reference_catch_up);
  r.get("start_at_speed", o.start_at_speed);
  r.get("turn_before_walk", o.turn_before_walk);
  r.get("brake_along_motion", o.brake_along_motion);
  r.get("enter_at_rest", o.enter_at_rest);
  r.get("keep_zone_drive", o.keep_zone_drive);
  r.get("retry_flight_frontiers", o.retry_flight_frontiers);
  r.get("set_aside_backoff", o.set_aside_backoff);
  r.get("no_views_on_climbed_flights", o.no_views_on_climbed_flights);
  r.get("climb_axis_anew", o.climb_axis_anew);
  r.get("no_progress_s", o.no_progress_s, Range{0.0, 600.0});
  r.get("stale_floor_s", o.stale_floor_s, Range{0.0, 3600.0});
  r.get("replan_only_if_faster", o.replan_only_if_faster);
  r.get("incremental_maintenance", o.incremental_maintenance);
}

constexpr EnumName<SensorType> kSensorTypes[] = {{"vlp16", SensorType::kVlp16},
                                                 {"mid360", SensorType::kMid360}};
constexpr EnumName<LinkTransport> kTransports[] = {{"dds", LinkTransport::kDds},
                                                   {"udp", LinkTransport::kUdp},
                                                   {"can", LinkTransport::kCan},
                                                   {"sim", LinkTransport::kSim}};

void read_sensor(SectionReader&& r, SensorConfig& o) {
  r.get_enum("type", o.type, kSensorTypes, Need::kRequired);
  {
    SectionReader m = r.section("mounting");
    m.get_list("xyz_m", o.mounting_xyz_m, Range{-2.0, 2.0});
    m.get_list_deg("rpy_deg", o.mounting_rpy_rad, Range{-180.0, 180.0});
  }
  r.get("min_range_m", o.min_range_m, Range{0.0, 10.0});
  r.get("max_range_m", o.max_range_m, Range{0.5, 300.0});
  r.get("scan_rate_hz", o.scan_rate_hz, Range{1.0, 50.0});
  r.get("sensor_address", o.sensor_address, check_ipv4_or_empty);
  r.get("host_address", o.host_address, check_ipv4);
  r.get("data_port", o.data_port, kPort);
  r.get("imu_port", o.imu_port, Range{0, 65535});
  r.get("rcvbuf_bytes", o.rcvbuf_bytes, Range{65536, 1 << 30});
}

void read_task(SectionReader&& r, TaskRate& o, bool event_driven) {
  // Event-driven tasks may give 0 (run on readiness); periodic ones need a rate.
  r.get("rate_hz", o.rate_hz, event_driven ? Range{0.0, 10000.0} : Range{0.1, 10000.0});
  r.get("budget_us", o.budget_us, Range{1, 10'000'000});
  r.get("priority", o.priority, Range{0, 99});
  r.get("cpu", o.cpu, Range{-1, 1023});
}

void read_rates(SectionReader&& r, RateTable& o) {
  read_task(r.section("ingest"), o.ingest, true);
  read_task(r.section("map"), o.map, false);
  read_task(r.section("plan"), o.plan, false);
  read_task(r.section("control"), o.control, false);
  read_task(r.section("watchdog"), o.watchdog, false);
  read_task(r.section("telemetry"), o.telemetry, false);
}

void read_safety(SectionReader&& r, SafetyConfig& o) {
  r.get("lidar_stale_s", o.lidar_stale_s, Range{0.01, 10.0});
  r.get("pose_stale_s", o.pose_stale_s, Range{0.005, 10.0});
  r.get("trajectory_stale_s", o.trajectory_stale_s, Range{0.05, 60.0});
  r.get("link_timeout_s", o.link_timeout_s, Range{0.01, 10.0});
  r.get("lookahead_s", o.lookahead_s, Range{0.1, 10.0});
  r.get("max_overruns", o.max_overruns, Range{1, 1000});
  r.get("turn_on_reference", o.turn_on_reference);
  r.get("turn_on_reference_full_m", o.turn_on_reference_full_m, Range{0.0, 2.0});
  r.get("turn_on_reference_zero_m", o.turn_on_reference_zero_m, Range{0.01, 2.0});
  r.get("lookahead_on_plan_grid", o.lookahead_on_plan_grid);
  r.get("reference_yaw_gate_rad", o.reference_yaw_gate_rad, Range{0.05, 3.0});
  r.get("reference_speed_lead_mps", o.reference_speed_lead_mps, Range{0.0, 5.0});
  r.get("check_body_turn", o.check_body_turn);
}

void read_link(SectionReader&& r, LinkConfig& o) {
  r.get_enum("transport", o.transport, kTransports, Need::kRequired);
  r.get("max_command_age_s", o.max_command_age_s, Range{0.001, 1.0});
  r.get("heartbeat_period_s", o.heartbeat_period_s, Range{0.01, 10.0});
  {
    SectionReader d = r.section("dds");
    d.get("domain_id", o.dds.domain_id, Range{0, 232});  // DDS RTPS port mapping limit
    d.get("interface", o.dds.interface, check_ifname);
    d.get("allow_multicast", o.dds.allow_multicast);
    d.get("peers", o.dds.peers, check_ipv4);
  }
  {
    SectionReader u = r.section("udp");
    u.get("robot_address", o.udp.robot_address, check_ipv4);
    u.get("robot_port", o.udp.robot_port, kPort);
    u.get("local_address", o.udp.local_address, check_ipv4);
    u.get("local_port", o.udp.local_port, kPort);
  }
  {
    SectionReader c = r.section("can");
    c.get("interface", o.can.interface, check_ifname_nonempty);
    c.get("fd_frames", o.can.fd_frames);
  }
}

void read_realtime(SectionReader&& r, RealtimeConfig& o) {
  r.get("sched_fifo", o.sched_fifo);
  r.get("mlockall", o.mlockall);
  r.get("cpu_pinning", o.cpu_pinning);
}

void read_root(SectionReader& r, Parameters& p) {
  r.known("include");  // handled by the loader before the sections
  read_robot(r.section("robot"), p.robot);
  read_map(r.section("map"), p.map);
  read_graph(r.section("graph"), p.graph);
  read_plan(r.section("plan"), p.plan);
  // One switch for the experimental blind stair climb, read by the map and the graph as well.
  p.map.pool_short_risers = p.map.seed_under_feet = p.graph.climb_frontiers =
      p.graph.root_off_graph = p.plan.climb_blind;
  read_sensor(r.section("sensor"), p.sensor);
  read_rates(r.section("rates"), p.rates);
  read_safety(r.section("safety"), p.safety);
  read_link(r.section("link"), p.link);
  read_realtime(r.section("realtime"), p.realtime);
}

// ---- cross-field checks ---------------------------------------------------------------------

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

class CrossChecker {
 public:
  CrossChecker(ReadContext& ctx, std::string top_file) : ctx_(ctx), top_(std::move(top_file)) {
    // A bad list element (`key[2]`) makes the whole list `key` bad.
    for (const ConfigError& e : ctx.errors()) bad_.insert(e.key.substr(0, e.key.find('[')));
  }

  // Requires `ok`; otherwise reports `msg` on key `a`, or on `b` when `b` was set in a later
  // layer (so the line points at what the user changed last). Skipped if either key already
  // failed its own check.
  void require(bool ok, const std::string& a, const std::string& b, const std::string& msg) {
    if (ok || bad_.count(a) != 0 || bad_.count(b) != 0) return;
    const Location none{top_, 0};
    const bool b_later = ctx_.set_order(b) > ctx_.set_order(a) &&
                         ctx_.origin(b, none).file != ctx_.origin(a, none).file;
    const std::string& key = (b_later || (!ctx_.was_set(a) && ctx_.was_set(b))) ? b : a;
    ctx_.error(ctx_.origin(key, Location{top_, 0}), key, msg);
  }

  void greater(double va, const std::string& a, double vb, const std::string& b) {
    require(va > vb, a, b, a + " = " + num(va) + " must be greater than " + b + " = " + num(vb));
  }

 private:
  ReadContext& ctx_;
  std::string top_;
  std::set<std::string> bad_;
};

void cross_check(const Parameters& p, ReadContext& ctx, const std::string& top) {
  CrossChecker c(ctx, top);
  c.greater(p.robot.body_height_m, "robot.body_height_m", p.robot.step_height_m,
            "robot.step_height_m");
  c.greater(p.map.max_range_m, "map.max_range_m", p.map.min_range_m, "map.min_range_m");
  c.greater(p.safety.turn_on_reference_zero_m, "safety.turn_on_reference_zero_m",
            p.safety.turn_on_reference_full_m, "safety.turn_on_reference_full_m");
  c.greater(p.map.log_odds_max, "map.log_odds_max", p.map.log_odds_occupied,
            "map.log_odds_occupied");
  c.greater(p.map.log_odds_occupied, "map.log_odds_occupied", p.map.log_odds_min,
            "map.log_odds_min");
  c.require(p.map.neighbourhood_radius_m >= p.map.voxel_size_m, "map.neighbourhood_radius_m",
            "map.voxel_size_m",
            "map.neighbourhood_radius_m = " + num(p.map.neighbourhood_radius_m) +
                " must be at least map.voxel_size_m = " + num(p.map.voxel_size_m));
  // Eq. 4: a candidate at distance r_e must be able to become a new node, not always be
  // swallowed by the clearance of the node it was sampled from.
  c.greater(p.graph.r_e_m, "graph.r_e_m", p.graph.node_clearance_m, "graph.node_clearance_m");
  c.require(p.graph.theta_min <= p.graph.probes, "graph.theta_min", "graph.probes",
            "graph.theta_min = " + std::to_string(p.graph.theta_min) +
                " open directions can never be reached with graph.probes = " +
                std::to_string(p.graph.probes));
  c.require(p.plan.max_candidates_k <= p.graph.viewpoints_per_cluster, "plan.max_candidates_k",
            "graph.viewpoints_per_cluster",
            "plan.max_candidates_k = " + std::to_string(p.plan.max_candidates_k) +
                " exceeds the viewpoints kept per cluster, graph.viewpoints_per_cluster = " +
                std::to_string(p.graph.viewpoints_per_cluster));
  c.require(p.plan.min_zone_nodes <= p.plan.zone_capacity, "plan.min_zone_nodes",
            "plan.zone_capacity",
            "plan.min_zone_nodes = " + std::to_string(p.plan.min_zone_nodes) +
                " exceeds plan.zone_capacity = " + std::to_string(p.plan.zone_capacity));
  // A single climbable step must not look like another floor (DESIGN §4.8).
  c.greater(p.plan.floor_change_dz_m, "plan.floor_change_dz_m", p.robot.step_height_m,
            "robot.step_height_m");
  c.greater(p.sensor.max_range_m, "sensor.max_range_m", p.sensor.min_range_m, "sensor.min_range_m");

  // Periodic tasks: the budget must fit in the period, else every run is an overrun.
  for (const RateTable::Row& row : p.rates.rows()) {
    const TaskRate& t = *row.rate;
    if (t.rate_hz <= 0.0) continue;
    const double period_us = 1e6 / t.rate_hz;
    const std::string key = "rates." + std::string(row.name) + ".budget_us";
    c.require(t.budget_us <= period_us, key, "rates." + std::string(row.name) + ".rate_hz",
              key + " = " + std::to_string(t.budget_us) + " exceeds the task period of " +
                  num(period_us) + " us (" + num(t.rate_hz) + " Hz)");
  }
  // Staleness limits shorter than the producer's period would stop the robot continuously.
  c.greater(p.safety.trajectory_stale_s, "safety.trajectory_stale_s", 1.0 / p.rates.plan.rate_hz,
            "rates.plan.rate_hz");
  c.greater(p.safety.pose_stale_s, "safety.pose_stale_s", 1.0 / p.rates.control.rate_hz,
            "rates.control.rate_hz");
  c.greater(p.safety.link_timeout_s, "safety.link_timeout_s", 1.0 / p.rates.control.rate_hz,
            "rates.control.rate_hz");

  if (p.link.transport == LinkTransport::kDds) {
    c.require(p.link.dds.allow_multicast || !p.link.dds.peers.empty(), "link.dds.peers",
              "link.dds.allow_multicast",
              "link.dds.peers is empty and link.dds.allow_multicast is false: no discovery");
  }
  if (p.link.transport == LinkTransport::kUdp) {
    const UdpLinkConfig& u = p.link.udp;
    const bool loopback = u.robot_address.rfind("127.", 0) == 0;
    c.require(!(loopback && u.robot_port == u.local_port), "link.udp.local_port",
              "link.udp.robot_port",
              "link.udp.local_port = " + std::to_string(u.local_port) +
                  " is also link.udp.robot_port on loopback: commands would loop back");
    c.require(u.local_port != p.sensor.data_port, "link.udp.local_port", "sensor.data_port",
              "link.udp.local_port = " + std::to_string(u.local_port) +
                  " is also sensor.data_port: LiDAR and robot state cannot share a port");
  }
}

// ---- loading and layering -----------------------------------------------------------------

constexpr int kMaxIncludeDepth = 8;

class Loader {
 public:
  Result finish(const std::string& top) {
    // A file that could not be read or parsed would only add confusing follow-up errors.
    if (!broken_) {
      ctx_.check_required();
      cross_check(params_, ctx_, top);
    }
    Result r;
    r.errors = ctx_.take_errors();
    // Errors in reading order of the files (base first), then by line.
    auto rank = [this](const ConfigError& e) {
      std::size_t i = 0;
      while (i < files_.size() && files_[i] != e.where.file) ++i;
      return std::make_pair(i, e.where.line);
    };
    std::stable_sort(r.errors.begin(), r.errors.end(),
                     [&](const ConfigError& x, const ConfigError& y) { return rank(x) < rank(y); });
    r.params = params_;
    r.origins = ctx_.origins();
    r.schema_keys.assign(ctx_.asked().begin(), ctx_.asked().end());
    r.files = std::move(files_);
    return r;
  }

  // Reads `path` and its includes. `from` is where it was included (line 0 for the top file).
  void apply_file(const std::string& path, const Location& from) {
    std::error_code ec;
    std::ifstream in;
    errno = 0;
    if (fs::is_directory(path, ec)) {
      errno = EISDIR;
    } else {
      in.open(path, std::ios::binary);
    }
    std::ostringstream text;
    if (in.is_open()) text << in.rdbuf();
    if (!in.is_open() || in.bad()) {
      const std::string why = errno != 0 ? std::strerror(errno) : "read error";
      broken_ = true;
      if (from.file.empty()) {
        ctx_.error(Location{path, 0}, "", "cannot read file: " + why);
      } else {
        ctx_.error(from, "include", "cannot read '" + path + "': " + why);
      }
      return;
    }
    apply_text(text.str(), path);
  }

  void apply_text(std::string_view text, const std::string& name) {
    YAML::Node root;
    try {
      root = YAML::Load(std::string(text));
    } catch (const YAML::Exception& e) {
      const int line = e.mark.is_null() ? 0 : e.mark.line + 1;
      ctx_.error(Location{name, line}, "", "malformed YAML: " + e.msg);
      broken_ = true;
      return;
    }
    if (!root.IsNull() && !root.IsMap()) {
      ctx_.error(Location{name, 1}, "",
                 "expected a mapping of sections (robot:, map:, ...) at the top level");
      broken_ = true;
      return;
    }
    auto file = std::make_shared<const std::string>(name);
    if (root.IsMap()) apply_includes(root, name);
    files_.push_back(name);                    // after its includes: base layers first
    SectionReader r(root, "", file, 0, ctx_);  // line 0: "absent" means the whole file
    read_root(r, params_);
  }

 private:
  void apply_includes(const YAML::Node& root, const std::string& name) {
    for (const auto& kv : root) {
      if (!kv.first.IsScalar() || kv.first.Scalar() != "include") continue;
      const int line = kv.first.Mark().line + 1;
      const Location at{name, line};
      std::vector<std::string> targets;
      bool ok = true;
      if (kv.second.IsScalar()) {
        targets.push_back(kv.second.Scalar());
      } else if (kv.second.IsSequence()) {
        for (const auto& e : kv.second) {
          if (e.IsScalar()) {
            targets.push_back(e.Scalar());
          } else {
            ok = false;
          }
        }
      } else {
        ok = false;
      }
      if (!ok) {
        ctx_.error(at, "include", "expected a file name or a list of file names");
        return;
      }
      for (const std::string& t : targets) include_one(t, at);
      return;  // a duplicate `include` key is reported by the root reader
    }
  }

  void include_one(const std::string& target, const Location& at) {
    fs::path p(target);
    if (p.is_relative()) p = fs::path(at.file).parent_path() / p;
    const std::string path = p.lexically_normal().string();
    std::error_code ec;
    const std::string id = fs::weakly_canonical(p, ec).string();
    for (const std::string& open : stack_) {
      if (open == id) {
        ctx_.error(at, "include", "'" + target + "' includes itself (include cycle)");
        return;
      }
    }
    if (stack_.size() >= kMaxIncludeDepth) {
      ctx_.error(at, "include", "includes nested deeper than " + std::to_string(kMaxIncludeDepth));
      return;
    }
    stack_.push_back(id);
    apply_file(path, at);
    stack_.pop_back();
  }

 public:
  void push_top(const std::string& name) {
    std::error_code ec;
    stack_.push_back(fs::weakly_canonical(fs::path(name), ec).string());
  }

 private:
  ReadContext ctx_;
  Parameters params_;
  std::vector<std::string> files_;
  bool broken_ = false;             // a file was unreadable, malformed or not a mapping
  std::vector<std::string> stack_;  // canonical paths of the files being read (cycle check)
};

}  // namespace

Result load(const std::string& path) {
  Loader l;
  l.push_top(path);
  l.apply_file(path, Location{});
  return l.finish(path);
}

Result load_string(std::string_view text, const std::string& name) {
  Loader l;
  l.push_top(name);
  l.apply_text(text, name);
  return l.finish(name);
}

std::string_view to_string(SensorType t) {
  switch (t) {
    case SensorType::kVlp16:
      return "vlp16";
    case SensorType::kMid360:
      return "mid360";
  }
  return "?";
}

std::string_view to_string(LinkTransport t) {
  switch (t) {
    case LinkTransport::kDds:
      return "dds";
    case LinkTransport::kUdp:
      return "udp";
    case LinkTransport::kCan:
      return "can";
    case LinkTransport::kSim:
      return "sim";
  }
  return "?";
}

}  // namespace storey::config
