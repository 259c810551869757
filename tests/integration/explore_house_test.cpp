// The full stack (firmware task table, map, graph, ExplorationPlanner, control, safety) explores
// the two-floor `house` scene in lockstep: with config/default.yaml the robot finishes the ground
// floor, climbs the flight blind onto the landing (plan.climb_blind) and explores the upper floor.
// The paper-literal pipeline (the session 9-11 switches off) is checked on the ground floor.
#include <cstdio>

#include <gtest/gtest.h>

#include "tests/integration/expectations.hpp"
#include "tools/sim/sim_run.hpp"

namespace storey::tools::sim {
namespace {

SimRunOptions house_options(double time_limit_s) {
  return quiet_run("house", 1, time_limit_s);
}

// Issue #9's bar: both floors of the house explored (the robot walks up the flight past the
// treads its pitched LiDAR cannot see, onto the landing), >= 90 % of each floor, no collision or
// fall, and bit-for-bit repeatability for a seed.
TEST(ExploreHouse, BothFloorsSafelyAndDeterministically) {
  const SimRunOptions o = house_options(400);
  const SimRunResult a = run_exploration(o);
  const RunMetrics& m = a.metrics;
  EXPECT_EQ(m.method, "storey");
  EXPECT_EQ(m.end_reason, a.end_reason);
  // Measured (seed 1, session 33, wall faces closed): complete at 140.5 s, floors 0.957 / 0.962.
  // Session 26: complete at 155.5 s, floors 0.964 / 0.958. Session 23: 181.5 s,
  // 0.961 / 0.954 (session 22, re-timed
  // trajectories on: 189.0 s, 0.962 / 0.953; session 18: 240.0 s, 0.966 / 0.961; session 12, before
  // the five switches session 18 turned on: 146.0 s, 0.968 / 0.957; docs/RESULTS.md).
  expect_every_floor_explored_safely(a, 2);
  EXPECT_GT(m.trajectory_length_m, 5.0);
  // The body beside its reference, every 10 ms (RunMetrics::tracking; seed 1, session 28: p50
  // 0.002, p99 0.039, max 0.060 m). The planner and the look-ahead check the reference's poses
  // with robot.body_margin_m (0.05 m): at p99 the body must stay within it.
  EXPECT_GT(m.tracking.samples, 5000u);
  EXPECT_LT(m.tracking.side_p99_m, 0.05);
  EXPECT_GT(m.tracking.side_max_m, m.tracking.side_p50_m);

  const SimRunResult b = run_exploration(o);
  const RunMetrics& n = b.metrics;
  // Everything but the latency profile (real CPU time) is a function of the inputs.
  EXPECT_EQ(a.end_reason, b.end_reason);
  EXPECT_EQ(m.exploration_time_s, n.exploration_time_s);
  EXPECT_EQ(m.trajectory_length_m, n.trajectory_length_m);
  EXPECT_EQ(m.traversable_coverage, n.traversable_coverage);
  EXPECT_EQ(m.traversable_volume_m3, n.traversable_volume_m3);
  EXPECT_EQ(m.occupied_volume_m3, n.occupied_volume_m3);
  EXPECT_EQ(m.safety_stops, n.safety_stops);
  EXPECT_EQ(m.coverage_over_time, n.coverage_over_time);
  EXPECT_EQ(m.tracking.side_max_m, n.tracking.side_max_m);
  EXPECT_EQ(m.tracking.samples, n.tracking.samples);
}

// The paper-literal pipeline (no blind climb, no phantom-frontier fixes, no retries) still
// explores the ground floor safely and ends complete: the switches are the only difference.
TEST(ExploreHouse, GroundFloorWithTheSwitchesOff) {
  SimRunOptions o = house_options(300);
  o.config =
      edited_default_config("storey_paper_literal.yaml",
                            {{"spill_is_surface: true ", "spill_is_surface: false"},
                             {"close_probes_at_holes: true ", "close_probes_at_holes: false"},
                             {"climb_blind: true ", "climb_blind: false"},
                             {"target_momentum: true ", "target_momentum: false"},
                             {"path_retries: 2", "path_retries: 0"},
                             {"flight_foot: true ", "flight_foot: false"},
                             {"brake_start: true ", "brake_start: false"},
                             {"lookahead_on_plan_grid: true ", "lookahead_on_plan_grid: false"},
                             {"keep_reachable_cut: true ", "keep_reachable_cut: false"},
                             {"surface_seen_from_above: true ", "surface_seen_from_above: false"},
                             {"stale_floor_s: 120.0", "stale_floor_s: 0.0"},
                             {"miss_needs_crossing: true ", "miss_needs_crossing: false"},
                             {"traj_retime: true ", "traj_retime: false"},
                             {"reference_clock: true ", "reference_clock: false"}});
  ASSERT_FALSE(o.config.empty()) << "config/default.yaml does not have the switches on";
  const SimRunResult a = run_exploration(o);
  const RunMetrics& m = a.metrics;
  EXPECT_TRUE(a.completed) << a.end_reason;
  EXPECT_EQ(m.collisions, 0u);
  EXPECT_EQ(m.falls, 0u);
  ASSERT_EQ(m.floors_total, 2);
  // Measured 0.948, complete at 116.0 s (seed 1, docs/RESULTS.md session 7-10 "default").
  EXPECT_GE(m.per_floor[0].traversable_coverage, 0.8);
  EXPECT_LT(m.exploration_time_s, 300.0);
}

// A baseline's run ends with its own reason: the goals it set aside, not the storey method's
// frontier clusters (which it never schedules).
TEST(ExploreHouse, ABaselineEndsNamingItsOwnSetAsideGoals) {
  SimRunOptions o;
  o.scene = "house";
  o.method = "nearest-frontier";
  o.time_limit_s = 300;
  o.progress_period_s = 0;
  o.progress = [](const std::string&) {};
  const SimRunResult a = run_exploration(o);
  ASSERT_TRUE(a.completed) << a.end_reason;
  EXPECT_NE(a.end_reason.find("(nearest-frontier: "), std::string::npos) << a.end_reason;
  EXPECT_NE(a.end_reason.find("goals set aside: "), std::string::npos) << a.end_reason;
  EXPECT_NE(a.end_reason.find(" without a trajectory, "), std::string::npos) << a.end_reason;
  EXPECT_NE(a.end_reason.find(" without progress)"), std::string::npos) << a.end_reason;
  EXPECT_EQ(a.end_reason.find("clusters"), std::string::npos) << a.end_reason;
}

// Methods and ablations are all available; what is refused is unknown names and an ablation
// (a switch of the storey method) combined with a baseline.
TEST(ExploreHouse, RefusesBadMethodAndAblation) {
  SimRunOptions o;
  o.scene = "house";
  o.method = "no-such-method";
  EXPECT_THROW(run_exploration(o), std::invalid_argument);
  o.method = "fael-like";
  o.ablation = "no-prior";
  EXPECT_THROW(run_exploration(o), std::invalid_argument);
  o.method = "storey";
  o.ablation = "no-such-thing";
  EXPECT_THROW(run_exploration(o), std::invalid_argument);
  o.ablation = "";
  o.scene = "no_such_scene";
  EXPECT_THROW(run_exploration(o), std::invalid_argument);
}

// A bad --config names the file, the line and the key before anything runs.
TEST(ExploreHouse, ABadConfigNamesItsKeyAndLine) {
  SimRunOptions o = house_options(10);
  o.config =
      edited_default_config("storey_bad_key.yaml", {{"climb_blind: true ", "climb_blind: tru  "}});
  ASSERT_FALSE(o.config.empty()) << "config/default.yaml has no plan.climb_blind: true";
  try {
    run_exploration(o);
    FAIL() << "a config with climb_blind: tru ran";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("storey_bad_key.yaml:"), std::string::npos) << what;
    EXPECT_NE(what.find("plan.climb_blind: expected true or false, got 'tru'"), std::string::npos)
        << what;
  }
}

TEST(ExploreHouse, MetricsNameTheMethodAndHowTheRunEnded) {
  RunMetrics m;
  m.method = "tare-like";
  m.ablation = "";
  m.completed = true;
  m.end_reason = "exploration complete at 1.0 s: \"quoted\"";
  const std::string j = metrics_json(m);
  EXPECT_NE(j.find("\"method\": \"tare-like\""), std::string::npos) << j;
  EXPECT_NE(j.find("\"ablation\": \"\""), std::string::npos);
  EXPECT_NE(j.find("\"completed\": true"), std::string::npos);
  EXPECT_NE(j.find("\"end_reason\": \"exploration complete at 1.0 s: \\\"quoted\\\"\""),
            std::string::npos)
      << j;
}

// With the phantom frontiers on walls' faces closed (graph.close_probes_at_wall_faces, on since
// session 33) a floor runs out of targets right after one failed climb: house seed 9's climb from
// the flight's foot went along an axis 0.2 m off the flight's middle, stopped on the flight, and
// the walk on along that axis met the side wall; without the two flight keys the run ends
// "complete" with the upper floor at 1.4 % (measured, session 33). plan.climb_axis_anew tries the
// walk on up the axis the robot faces, found anew, and plan.retry_flight_frontiers retries a
// flight's frontiers before "complete" (house seed 5: a climb refused at the foot, the frontier
// set aside, "complete" at 61 s without it). Since session 39 LocalPlanner::to_found_flight (a
// flight found that never led up is gone to before "no target" is the verdict) also catches it:
// without the two keys house seed 9 now explores both floors too (upper floor 95.3 %).
TEST(ExploreHouse, WithWallFacesClosedAFailedClimbIsTriedAgain) {
  SimRunOptions o = quiet_run("house", 9, 400);
  o.config = edited_default_config(
      "house_no_flight_keys.yaml",
      {{"close_probes_at_wall_faces: true ", "close_probes_at_wall_faces: true "},
       {"retry_flight_frontiers: true ", "retry_flight_frontiers: false "},
       {"climb_axis_anew: true ", "climb_axis_anew: false "}});
  ASSERT_FALSE(o.config.empty()) << "config/default.yaml does not have the three keys on";
  expect_every_floor_explored_safely(run_exploration(o), 2);
  o.config.clear();  // the defaults
  expect_every_floor_explored_safely(run_exploration(o), 2);
  o.seed = 5;
  expect_every_floor_explored_safely(run_exploration(o), 2);
}

// The run record says why the robot went where it went: plan.csv holds one row per new trajectory
// (the planner's reason, the target), and diagnostics.md explains each C_exp frontier left by the
// unknown that opens its probes (20 s into the house: frontiers everywhere).
TEST(ExploreHouse, TheRunRecordLogsThePlanAndExplainsTheFrontiersLeft) {
  SimRunOptions o = house_options(20);
  o.out_dir = testing::TempDir() + "/house_record";
  const SimRunResult a = run_exploration(o);
  std::ifstream plan(o.out_dir + "/plan.csv");
  ASSERT_TRUE(plan.good()) << "no plan.csv in " << o.out_dir;
  std::string line;
  std::getline(plan, line);
  EXPECT_EQ(line, "t_s,reason,cluster,target_x_m,target_y_m,target_z_m");
  int rows = 0;
  double last_t = -1;
  while (std::getline(plan, line)) {
    double t = -1, x = 0, y = 0, z = 0;
    int cluster = -2;
    char reason[128] = {};
    ASSERT_EQ(
        std::sscanf(line.c_str(), "%lf,%127[^,],%d,%lf,%lf,%lf", &t, reason, &cluster, &x, &y, &z),
        6)
        << line;
    EXPECT_GE(t, last_t);
    EXPECT_LE(t, 20.0);
    EXPECT_GT(std::string(reason).size(), 3u) << line;
    EXPECT_GE(cluster, -1);
    last_t = t;
    ++rows;
  }
  EXPECT_GE(rows, 2);
  std::ifstream d(o.out_dir + "/diagnostics.md");
  std::stringstream ds;
  ds << d.rdbuf();
  const std::string diag = ds.str();
  ASSERT_NE(diag.find("Open C_exp probes"), std::string::npos) << diag.substr(0, 2000);
  EXPECT_NE(diag.find(" deg: unknown"), std::string::npos) << diag.substr(0, 2000);
}

}  // namespace
}  // namespace storey::tools::sim
