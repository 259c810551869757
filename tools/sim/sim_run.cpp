#include "tools/sim/sim_run.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "config/parameters.hpp"
#include "core/graph/graph_export.hpp"
#include "core/map/ply_export.hpp"
#include "firmware/autonomy.hpp"
#include "firmware/commands.hpp"
#include "rt/clock.hpp"
#include "tools/sim/exploration_diagnostics.hpp"
#include "tools/sim/ground_truth.hpp"
#include "tools/sim/render.hpp"
#include "tools/sim/sim_platform.hpp"
#include "tools/sim/world_sim.hpp"

namespace storey::tools::sim {

namespace fs = std::filesystem;
using firmware::Autonomy;

const std::vector<std::string>& known_methods() {
  static const std::vector<std::string> m = {"storey", "nearest-frontier", "fael-like",
                                             "tare-like"};
  return m;
}
const std::vector<std::string>& known_ablations() {
  static const std::vector<std::string> a = {"no-tentative",       "no-c-sur", "no-c-exp",
                                             "boundary-frontiers", "no-prior", "no-incremental"};
  return a;
}

namespace {

config::Parameters load_parameters(const std::string& path) {
  std::string file = path;
  if (file.empty()) {
    file = firmware::default_config_path();
    if (!fs::exists(file)) return config::Parameters{};  // installed without the tree: defaults
  }
  config::Result r = config::load(file);
  if (!r.ok()) {
    const auto& e = r.errors.front();
    throw std::invalid_argument("--config " + e.to_string() + " (" +
                                std::to_string(r.errors.size()) +
                                " error(s); see storey check-config " + file + ")");
  }
  return r.params;
}

void apply_ablation(const std::string& name, config::Parameters& p) {
  if (name.empty()) return;
  if (name == "no-tentative")
    p.graph.use_tentative = false;
  else if (name == "no-c-sur")
    p.graph.use_c_sur = false;
  else if (name == "no-c-exp")
    p.graph.use_c_exp = false;
  else if (name == "boundary-frontiers")
    p.graph.boundary_frontiers = true;
  else if (name == "no-prior")
    p.plan.use_prior = false;  // paper Table IV: no cross-floor prior
  else if (name == "no-incremental")
    p.plan.incremental_maintenance = false;  // prior without split / reassignment (IV-B)
  else
    throw std::invalid_argument("--ablation " + name +
                                ": unknown (known: no-tentative, no-c-sur, "
                                "no-c-exp, boundary-frontiers, no-prior, no-incremental)");
}

// Traversable / occupied voxels of the map as ground-truth keys (same floor(p / res) keys).
void observed_keys(const core::map::TraversabilityMap& map, std::vector<VoxelKey>& trav,
                   std::vector<VoxelKey>& occ) {
  trav.clear();
  occ.clear();
  map.view().for_each_occupied([&](const core::map::VoxelKey& k, const core::map::Cell& c, auto*) {
    occ.push_back({k.x, k.y, k.z});
    if (c.state == core::map::TravState::kTraversable) trav.push_back({k.x, k.y, k.z});
  });
}

std::string fmt(const char* f, double v) {
  char b[64];
  std::snprintf(b, sizeof b, f, v);
  return b;
}

struct RecordInputs {
  const SimRunOptions* opt;
  const Scene* scene;
  const GroundTruth* gt;
  const Autonomy* autonomy;
  const std::vector<Eigen::Vector3d>* path;
  const std::string* tracking_csv;  // tracking.csv's rows (10 Hz)
  const std::string* plan_csv;      // plan.csv's rows (one per new trajectory)
  const SimRunResult* result;
  std::string error;  // set when the run failed with an exception
};

// Top-down floor picture / side view with the map, graph, frontiers and the robot's path.
void draw_overlays(View& v, const RecordInputs& in, bool top_down, double z_lo, double z_hi) {
  const auto& map = in.autonomy->map_for_record();
  const double res = map.options().voxel_size_m;
  const Rgb trav{60, 170, 60}, untrav{210, 60, 50}, conf{20, 110, 20}, tent{40, 90, 220},
      hyp{150, 150, 150}, frontier{230, 0, 200}, path{250, 140, 0};
  map.view().for_each_occupied([&](const core::map::VoxelKey& k, const core::map::Cell& c, auto*) {
    const Eigen::Vector3d p((k.x + 0.5) * res, (k.y + 0.5) * res, (k.z + 0.5) * res);
    if (p.z() < z_lo || p.z() > z_hi) return;
    if (c.state == core::map::TravState::kTraversable)
      v.point(p, trav, 0);
    else if (c.state == core::map::TravState::kUntraversable && top_down)
      v.point(p, untrav, 0);
  });
  if (auto w = in.autonomy->world()) {
    const auto& g = w->graph;
    auto in_band = [&](const Eigen::Vector3f& p) { return p.z() >= z_lo && p.z() <= z_hi; };
    for (size_t e = 0; e < g.edge_capacity(); ++e) {
      const auto& ge = g.edge(core::graph::EdgeId(e));
      if (!ge.alive) continue;
      const Eigen::Vector3f a = g.node(ge.a).p_m, b = g.node(ge.b).p_m;
      if (!in_band(a) && !in_band(b)) continue;
      const Rgb c = ge.state == core::graph::ElementState::kConfirmed   ? conf
                    : ge.state == core::graph::ElementState::kTentative ? tent
                                                                        : hyp;
      v.line(a.cast<double>(), b.cast<double>(), c);
    }
    for (size_t i = 0; i < g.node_capacity(); ++i) {
      const auto& n = g.node(core::graph::NodeId(i));
      if (!n.alive || !in_band(n.p_m)) continue;
      v.point(n.p_m.cast<double>(),
              n.frontier()                                       ? frontier
              : n.state == core::graph::ElementState::kConfirmed ? conf
                                                                 : tent,
              n.frontier() ? 2 : 1);
    }
  }
  std::vector<Eigen::Vector3d> seg;
  for (const auto& p : *in.path) {
    if (p.z() >= z_lo && p.z() <= z_hi) {
      seg.push_back(p);
    } else if (!seg.empty()) {
      v.polyline(seg, path);
      seg.clear();
    }
  }
  if (!seg.empty()) v.polyline(seg, path);
  if (!in.path->empty()) v.point(in.path->front(), {0, 0, 0}, 3);
}

void write_record(const RecordInputs& in, std::vector<std::string>& written) {
  const std::string dir = in.opt->out_dir;
  fs::create_directories(dir);
  const auto& m = in.result->metrics;
  write_metrics_json(m, dir + "/metrics.json");
  written.push_back("metrics.json");
  const auto& map = in.autonomy->map_for_record();
  const auto ply = core::map::write_ply_occupied(map.view(), dir + "/map.ply");
  if (ply.ok) written.push_back("map.ply");
  std::string err;
  if (auto w = in.autonomy->world()) {
    if (core::graph::write_text_file(dir + "/graph.json",
                                     core::graph::to_json(w->graph, &w->clusters, &w->viewpoints),
                                     &err))
      written.push_back("graph.json");
  }
  if (in.autonomy->trace().write_chrome_json(dir + "/trace.json", &err))
    written.push_back("trace.json");
  const std::string latency = const_cast<Autonomy*>(in.autonomy)->scheduler().report();
  {
    std::ofstream f(dir + "/latency.md");
    f << "# Per-task latency (lockstep: exec times are real CPU time, release times "
         "virtual)\n\n```\n"
      << latency << "```\n";
    written.push_back("latency.md");
  }
  {
    std::ofstream f(dir + "/tracking.csv");
    f << "t_s,x_m,y_m,z_m,yaw_deg,trajectory,tau_s,lag_s,ref_x_m,ref_y_m,ref_yaw_deg,ahead_m,"
         "left_m\n"
      << *in.tracking_csv;
    if (f) written.push_back("tracking.csv");
  }
  {
    std::ofstream f(dir + "/plan.csv");
    f << firmware::kPlanLogHeader << "\n" << *in.plan_csv;
    if (f) written.push_back("plan.csv");
  }
  // Pictures: one top-down view per ground-truth floor, one side view.
  std::vector<std::string> pictures;
  const auto& floors = in.gt->floors();
  for (size_t f = 0; f < floors.size(); ++f) {
    View v = render_floor(*in.gt, int(f));
    const double z = floors[f].z_m;
    const double next = f + 1 < floors.size() ? floors[f + 1].z_m : z + 3.0;
    draw_overlays(v, in, true, z - 0.3, std::min(z + 1.0, next - 0.3));
    const std::string name = "floor_" + std::to_string(f) + ".png";
    v.save_png(dir + "/" + name);
    pictures.push_back(name);
  }
  {
    View v = render_side(*in.gt);
    draw_overlays(v, in, false, -1e9, 1e9);
    v.save_png(dir + "/side.png");
    pictures.push_back("side.png");
  }
  for (const auto& p : pictures) written.push_back(p);
  {
    std::ofstream d(dir + "/diagnostics.md");
    d << exploration_diagnostics(*in.autonomy, *in.gt,
                                 in.path->empty() ? Eigen::Vector3d::Zero() : in.path->back());
    written.push_back("diagnostics.md");
  }

  // report.md ties it together.
  std::ofstream r(dir + "/report.md");
  r << "# storey sim: " << in.scene->name << "\n\n";
  r << "Command: `storey sim --scene " << in.opt->scene << " --method " << in.opt->method
    << " --sensor " << in.opt->sensor << " --seed " << in.opt->seed << " --time-limit "
    << in.opt->time_limit_s << (in.opt->ablation.empty() ? "" : " --ablation " + in.opt->ablation)
    << "` (commit " << m.commit << ")\n\n";
  r << "Outcome: **" << (m.success ? "success" : "no success") << "** - " << in.result->end_reason
    << "\n\n";
  if (!in.error.empty()) r << "Run failed: `" << in.error << "`\n\n";
  r << "| metric | value |\n|---|---|\n";
  r << "| exploration time | " << fmt("%.1f s", m.exploration_time_s) << " |\n";
  r << "| trajectory length | " << fmt("%.1f m", m.trajectory_length_m) << " |\n";
  r << fmt("| walking (> %.1f m/s) | ", kWalkingSpeed) << fmt("%.1f s", m.walking_time_s) << ", "
    << fmt("%.0f %% of the time", 100 * m.walking_time_s / std::max(m.exploration_time_s, 1e-9))
    << ", " << fmt("%.2f m/s", m.trajectory_length_m / std::max(m.walking_time_s, 1e-9))
    << " path length per walking second |\n";
  r << "| traversable coverage (ground truth) | " << fmt("%.1f %%", 100 * m.traversable_coverage)
    << " |\n";
  r << "| floors explored / total | " << m.floors_explored << " / " << m.floors_total << " |\n";
  r << "| traversable volume (observed / truth) | " << fmt("%.2f", m.traversable_volume_m3) << " / "
    << fmt("%.2f m^3", m.gt_traversable_volume_m3) << " |\n";
  r << "| occupied volume (observed / truth) | " << fmt("%.2f", m.occupied_volume_m3) << " / "
    << fmt("%.2f m^3", m.gt_occupied_volume_m3) << " |\n";
  r << "| collisions / falls / safety stops | " << m.collisions << " / " << m.falls << " / "
    << m.safety_stops << " |\n";
  r << "| body beside its reference: p50 / p99 / max (most ahead of it) | "
    << fmt("%.2f", m.tracking.side_p50_m) << " / " << fmt("%.2f", m.tracking.side_p99_m) << " / "
    << fmt("%.2f m", m.tracking.side_max_m) << fmt(" (%.2f m)", m.tracking.ahead_max_m) << " |\n\n";
  r << "## Floors\n\n| floor | z [m] | coverage | time to 90 % [s] |\n|---|---|---|---|\n";
  for (size_t f = 0; f < m.per_floor.size(); ++f)
    r << "| " << f << " | " << fmt("%.2f", m.per_floor[f].z_m) << " | "
      << fmt("%.1f %%", 100 * m.per_floor[f].traversable_coverage) << " | "
      << (m.per_floor[f].time_s >= 0 ? fmt("%.1f", m.per_floor[f].time_s) : std::string("-"))
      << " |\n";
  r << "\n## Latency per task\n\n| task | p50 [ms] | p99 [ms] | max [ms] | overruns "
       "|\n|---|---|---|---|---|\n";
  for (const auto& l : m.latency)
    r << "| " << l.task << " | " << fmt("%.3f", l.p50_ms) << " | " << fmt("%.3f", l.p99_ms) << " | "
      << fmt("%.3f", l.max_ms) << " | " << l.overruns << " |\n";
  r << "\nFull table: [latency.md](latency.md); trace: [trace.json](trace.json) (open in "
       "https://ui.perfetto.dev).\n\n";
  r << "## Pictures\n\nMap: traversable green, untraversable red; graph: confirmed dark green, "
       "tentative blue; frontier nodes magenta; robot path orange (start: black dot).\n\n";
  for (const auto& p : pictures) r << "![" << p << "](" << p << ")\n\n";
  r << "## Files\n\n";
  for (const auto& w : written) r << "- [" << w << "](" << w << ")\n";
  if (!in.result->log.empty()) {
    r << "\n## Firmware log\n\n```\n";
    for (const auto& l : in.result->log) r << l << "\n";
    r << "```\n";
  }
}

// The body against its reference pose on the trajectory the control task follows (nullopt, with
// *why, when it follows none or one the plan task has already replaced). The planner and the
// control look-ahead check the reference's poses, not the body's: a body off its reference
// meets what those checks cleared.
struct ReferenceOffset {
  core::plan::BodyPose ref;
  double ahead_m = 0, left_m = 0, yaw_off_rad = 0;
};
std::optional<ReferenceOffset> reference_offset(const firmware::Autonomy& a, const RobotState& rs,
                                                const char** why = nullptr) {
  const auto traj = a.trajectory();
  const firmware::TrajectoryProgress pr = a.trajectory_progress();
  const char* no = !traj || traj->trajectory.empty() ? "no trajectory"
                   : pr.id != traj->id               ? "following an earlier trajectory"
                                                     : nullptr;
  if (no) {
    if (why) *why = no;
    return std::nullopt;
  }
  ReferenceOffset o;
  o.ref = traj->trajectory.pose(pr.tau_s);
  const Eigen::Vector2d d = rs.position.head<2>() - o.ref.foot_m.head<2>();
  const double c = std::cos(o.ref.yaw_rad), s = std::sin(o.ref.yaw_rad);
  o.ahead_m = c * d.x() + s * d.y();
  o.left_m = -s * d.x() + c * d.y();
  o.yaw_off_rad = std::remainder(rs.yaw - o.ref.yaw_rad, 2 * M_PI);
  return o;
}

// For the collision and fall lines of the log.
std::string against_reference(const firmware::Autonomy& a, const RobotState& rs) {
  const char* why = "";
  const auto o = reference_offset(a, rs, &why);
  if (!o) return std::string("; ") + why;
  char buf[200];
  std::snprintf(buf, sizeof buf,
                "; reference (%.2f, %.2f) m, yaw %.0f deg: body %.2f m ahead, %.2f m left, "
                "%.0f deg off",
                o->ref.foot_m.x(), o->ref.foot_m.y(), o->ref.yaw_rad * 180 / M_PI, o->ahead_m,
                o->left_m, o->yaw_off_rad * 180 / M_PI);
  return buf;
}
}  // namespace

SimRunResult run_exploration(const SimRunOptions& opt) {
  if (std::find(known_methods().begin(), known_methods().end(), opt.method) ==
      known_methods().end())
    throw std::invalid_argument(
        "--method " + opt.method +
        ": unknown (known: storey, nearest-frontier, fael-like, tare-like)");
  if (opt.method != "storey" && !opt.ablation.empty())
    throw std::invalid_argument(
        "--ablation " + opt.ablation +
        ": ablations switch parts of the storey method; not with --method " + opt.method);
  if (opt.sensor != "vlp16" && opt.sensor != "mid360")
    throw std::invalid_argument("--sensor " + opt.sensor + ": expected vlp16 or mid360");
  if (!(opt.time_limit_s > 0)) throw std::invalid_argument("--time-limit must be > 0");
  config::Parameters params = load_parameters(opt.config);
  apply_ablation(opt.ablation, params);

  Scene scene;
  try {
    scene = load_scene(opt.scene);
  } catch (const std::exception& e) {
    throw std::invalid_argument(std::string("--scene ") + opt.scene + ": " + e.what());
  }
  if (opt.start) scene.start = opt.start;
  GroundTruthOptions go;
  go.resolution = params.map.voxel_size_m;
  go.step_height = params.robot.step_height_m;
  go.max_slope_deg = params.robot.max_slope_rad * 180.0 / M_PI;
  go.body_clearance = params.robot.body_height_m + params.robot.body_margin_m;
  go.collision_radius = params.map.collision_radius_m;  // truth mirrors the map's R_col
  const GroundTruth gt(scene.mesh, scene.start, go);

  SimOptions so;
  so.seed = opt.seed;
  so.lidar.type = opt.sensor == "mid360" ? LidarType::mid360 : LidarType::vlp16;
  so.start = scene.start ? scene.start : std::optional<StartPose>(gt.start());
  WorldSim world(scene, so);
  SimPlatform platform(world);
  rt::VirtualClock clock(0);

  SimRunResult res;
  firmware::AutonomyOptions ao;
  ao.params = params;
  ao.seed = opt.seed;
  ao.method = opt.method;
  ao.fov =
      opt.sensor == "mid360" ? core::graph::SensorFov::mid360() : core::graph::SensorFov::vlp16();
  ao.stop_on_overruns = false;  // lockstep: see AutonomyOptions
  auto progress = opt.progress ? opt.progress
                               : std::function<void(const std::string&)>([](const std::string& s) {
                                   std::fprintf(stderr, "%s\n", s.c_str());
                                 });
  ao.log = [&](const std::string& line) {
    res.log.push_back(line);
    progress("  firmware: " + line);
  };
  std::string plan_csv;  // every new trajectory: why and toward what (plan.csv)
  ao.plan_log = [&](const std::string& row) { plan_csv.append(row).push_back('\n'); };
  Autonomy autonomy(platform, clock, ao);

  std::vector<Eigen::Vector3d> path;
  CoverageTimeline timeline;
  std::vector<VoxelKey> trav, occ;
  auto sample_coverage = [&](double t) {
    observed_keys(autonomy.map_for_record(), trav, occ);
    const Coverage c = compute_coverage(gt, trav, occ);
    timeline.add(t, c);
    return c;
  };

  constexpr std::int64_t kSliceNs = 10'000'000;  // 10 ms: world stepped at 100 Hz
  const std::int64_t limit_ns = std::int64_t(std::llround(opt.time_limit_s * 1e9));
  const std::int64_t progress_ns = std::int64_t(std::llround(opt.progress_period_s * 1e9));
  std::int64_t t_ns = 0, next_progress = progress_ns, next_path = 0;
  uint32_t collisions_seen = 0, falls_seen = 0;
  std::vector<float> side_m;  // |body to reference, sideways| every slice (RunMetrics::tracking)
  std::string tracking_csv;   // the body and its reference at 10 Hz (tracking.csv)
  double ahead_max_m = 0;
  std::string error;
  try {
    for (;;) {
      autonomy.run_until(clock, t_ns + kSliceNs);  // firmware sees the world at t
      platform.step(double(kSliceNs) * 1e-9);      // world: [t, t + slice) with the command
      t_ns += kSliceNs;
      const double t = double(t_ns) * 1e-9;
      // Every collision and fall is logged where it happened (the metrics only count them).
      if (const auto& rs = world.robot_state();
          rs.collisions != collisions_seen || rs.falls != falls_seen) {
        char line[200];
        std::snprintf(line, sizeof line,
                      "  sim: t=%.2f s: %s at (%.2f, %.2f, %.2f) m, yaw %.0f deg, pitch %.0f deg, "
                      "roll %.0f deg",
                      t, rs.collisions != collisions_seen ? "body collision" : "fall",
                      rs.position.x(), rs.position.y(), rs.position.z(), rs.yaw * 180 / M_PI,
                      rs.pitch * 180 / M_PI, rs.roll * 180 / M_PI);
        progress(std::string(line).append(against_reference(autonomy, rs)));
        collisions_seen = rs.collisions;
        falls_seen = rs.falls;
      }
      const auto o = reference_offset(autonomy, world.robot_state());
      if (o) {
        side_m.push_back(float(std::abs(o->left_m)));
        ahead_max_m = std::max(ahead_max_m, o->ahead_m);
      }
      if (t_ns % 100'000'000 == 0 && !opt.out_dir.empty()) {
        const RobotState& rs = world.robot_state();
        const firmware::TrajectoryProgress pr = autonomy.trajectory_progress();
        char row[256];
        int n = std::snprintf(row, sizeof row, "%.2f,%.3f,%.3f,%.3f,%.1f,%llu,%.2f,%.2f", t,
                              rs.position.x(), rs.position.y(), rs.position.z(),
                              rs.yaw * 180 / M_PI, (unsigned long long)pr.id, pr.tau_s, pr.lag_s);
        if (o)
          std::snprintf(row + n, sizeof row - size_t(n), ",%.3f,%.3f,%.1f,%.3f,%.3f\n",
                        o->ref.foot_m.x(), o->ref.foot_m.y(), o->ref.yaw_rad * 180 / M_PI,
                        o->ahead_m, o->left_m);
        else
          std::snprintf(row + n, sizeof row - size_t(n), ",,,,,\n");
        tracking_csv += row;
      }
      if (t_ns >= next_path) {
        path.push_back(world.robot_state().position);
        next_path += 200'000'000;  // 5 Hz
      }
      const firmware::ExplorationStatus st = autonomy.status();
      const bool stranded = st.state == firmware::ExplorationState::kStranded;
      const bool done = st.state == firmware::ExplorationState::kComplete || stranded;
      if (progress_ns > 0 && (t_ns >= next_progress || done)) {
        next_progress += progress_ns;
        const Coverage c = sample_coverage(t);
        char line[384];
        std::snprintf(
            line, sizeof line,
            "[sim %7.1f s] coverage %5.1f %%  floor %d  nodes %u  frontiers %u (clusters %u)"
            "  stops %llu  plan %s (%s)%s",
            t, 100 * c.traversable_coverage, st.floor_hint, st.nodes, st.frontier_nodes,
            st.clusters, (unsigned long long)autonomy.safety_stops(),
            core::plan::to_string(st.last_plan), st.plan_reason,
            firmware::describe_target(st).c_str());
        progress(line);
      }
      if (done) {
        res.completed = !stranded;
        char why[320];
        if (stranded)
          std::snprintf(why, sizeof why,
                        "stranded at %.1f s: %s, but %u of %u clusters are unreachable from the "
                        "robot's node, in a part of the graph of %u of %u nodes",
                        t, st.plan_reason, st.clusters_unreachable, st.clusters,
                        st.robot_component_nodes, st.nodes);
        else if (st.goals_stood_at >= 0)  // a baseline: its own goals, not the storey clusters
          std::snprintf(why, sizeof why,
                        "exploration complete at %.1f s: %s (%s: goals set aside: %d stood at, "
                        "%d overdue, %d without a trajectory, %d without progress)",
                        t, st.plan_reason, st.method, st.goals_stood_at, st.goals_overdue,
                        st.goals_no_trajectory, st.goals_no_progress);
        else
          std::snprintf(why, sizeof why,
                        "exploration complete at %.1f s: %s (%u clusters, %u set aside as "
                        "unobservable, %u unreachable)",
                        t, st.plan_reason, st.clusters, st.clusters_set_aside,
                        st.clusters_unreachable);
        res.end_reason = why;
        break;
      }
      if (t_ns >= limit_ns) {
        res.end_reason = fmt("time limit reached (%.0f s simulated)", opt.time_limit_s);
        break;
      }
    }
  } catch (const std::exception& e) {
    error = e.what();
    res.end_reason = "run failed: " + error;
  }
  path.push_back(world.robot_state().position);
  const double t_end = double(t_ns) * 1e-9;

  // Metrics (DESIGN §7).
  const Coverage final_cov = sample_coverage(t_end);
  RunMetrics& m = res.metrics;
  fill_from_truth(gt, final_cov, timeline, 0.9, m);
  const RobotState& rs = world.robot_state();
  m.exploration_time_s = t_end;
  m.trajectory_length_m = rs.distance;
  m.walking_time_s = rs.walking_s;
  m.collisions = rs.collisions;
  m.falls = rs.falls;
  m.safety_stops = uint32_t(autonomy.safety_stops());
  if (!side_m.empty()) {
    const auto at = [&](double q) {
      auto k = side_m.begin() + std::ptrdiff_t(q * double(side_m.size() - 1));
      std::nth_element(side_m.begin(), k, side_m.end());
      return double(*k);
    };
    m.tracking.side_p50_m = at(0.5);
    m.tracking.side_p99_m = at(0.99);
    m.tracking.side_max_m = at(1.0);
    m.tracking.ahead_max_m = ahead_max_m;
    m.tracking.samples = side_m.size();
  }
  for (const auto& tr : autonomy.scheduler().reports()) {
    LatencyMetrics l;
    l.task = tr.name;
    l.p50_ms = double(tr.exec.p50_ns) * 1e-6;
    l.p99_ms = double(tr.exec.p99_ns) * 1e-6;
    l.max_ms = double(tr.exec.max_ns) * 1e-6;
    l.overruns = tr.overruns;
    m.latency.push_back(l);
  }
  m.method = opt.method;
  m.commit = firmware::build_commit();
  m.ablation = opt.ablation;
  m.completed = res.completed;
  m.end_reason = res.end_reason;
  m.success = res.completed && error.empty() && m.floors_explored == m.floors_total &&
              m.collisions == 0 && m.falls == 0;

  if (!opt.out_dir.empty()) {
    RecordInputs ri{&opt, &scene, &gt, &autonomy, &path, &tracking_csv, &plan_csv, &res, error};
    std::vector<std::string> written;
    write_record(ri, written);
    res.report_path = opt.out_dir + "/report.md";
  }
  return res;
}

}  // namespace storey::tools::sim
