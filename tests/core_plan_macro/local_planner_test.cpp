// LocalPlanner's set-aside frontier nodes (issue 9 diagnostics): they expire when the map near
// them changes, or after a while once the robot has moved; never on an unchanged map with the
// robot standing still.
#include "core/plan/local_planner.hpp"

#include <algorithm>
#include <cstdio>
#include <optional>
#include <string>

#include <gtest/gtest.h>

#include <functional>

#include "macro_world.hpp"

using namespace storey::core::plan;
using storey::core::RobotModel;
using storey::test::macro::Harness;
using storey::test::macro::World;

namespace {

// A 40 m corridor (6 m wide): one scan from the middle leaves a frontier at each open end.
World corridor() {
  World w;
  w.add({-20, -3, -0.2f}, {20, 3, 0});
  w.add({-20, -3.2f, 0}, {20, -3, 2.5f});
  w.add({-20, 3, 0}, {20, 3.2f, 2.5f});
  return w;
}

// One scan of w from foot; true if it left frontier clusters at both ends.
bool scan_from(Harness& h, const World& w, const Eigen::Vector3f& foot) {
  h.observe(w, foot, 40000, 1);
  return h.clusters.clusters().size() >= 2u;
}

LocalPlanInput input(const Harness& h, const storey::core::map::MapView& view,
                     const Eigen::Vector3f& foot, double t) {
  LocalPlanInput in;
  in.view = &view;
  in.graph = &h.graph;
  in.clusters = &h.clusters.clusters();
  in.viewpoints = &h.viewpoints.viewpoints();
  in.robot_foot_m = foot.cast<double>();
  in.t_s = t;
  return in;
}

// Plans to a cluster, then lets the trajectory run late without the robot moving, until a
// cluster is set aside (overdue, or still a frontier once the robot stood at it twice).
// Returns the set-aside positions and the time.
struct SetAside {
  std::vector<Eigen::Vector3f> p;
  double t = 0;
};
SetAside set_aside_one(LocalPlanner& lp, const Harness& h, const Eigen::Vector3f& foot,
                       double t0 = 0) {
  SetAside s;
  const auto view = h.map.view();
  double t = t0;
  for (int k = 0; k < 8 && lp.set_aside().empty(); ++k) {
    const LocalPlanResult r = lp.plan(input(h, view, foot, t));
    t = r.status == LocalPlanStatus::kNewTrajectory ? r.trajectory.t_end() + 10.0 : t + 10.0;
  }
  EXPECT_FALSE(lp.set_aside().empty());
  if (lp.set_aside().empty()) return s;
  s.t = lp.set_aside().front().t_s;
  for (const SetAsideEntry& e : lp.set_aside()) {
    EXPECT_EQ(e.cluster_id, lp.set_aside().front().cluster_id);
    EXPECT_EQ(e.t_s, s.t);
    EXPECT_EQ(e.robot_m, foot);
    s.p.push_back(e.p_m);
  }
  return s;
}

// Set-asides that expire after 30 s once the robot stands more than 2 m from where it was.
LocalPlannerOptions timed_expiry() {
  LocalPlannerOptions o;
  o.set_aside_expiry_s = 30.0;
  o.set_aside_expiry_move_m = 2.0;
  return o;
}

size_t still_set_aside(const LocalPlanner& lp, const SetAside& s) {
  size_t n = 0;
  for (const Eigen::Vector3f& p : s.p) n += lp.set_aside_at(p) != nullptr;
  return n;
}

}  // namespace

TEST(LocalPlanner, SetAsideStaysOnAnUnchangedMapAndExpiresWhereTheMapChanges) {
  const World w = corridor();
  Harness h;
  const Eigen::Vector3f foot(0, 0, 0);
  ASSERT_TRUE(scan_from(h, w, foot));
  LocalPlanner lp(RobotModel{}, PlanOptions{}, 0.1);
  const SetAside s = set_aside_one(lp, h, foot);
  ASSERT_FALSE(s.p.empty());

  // Same map, robot still, long after: nothing expires.
  {
    const auto view = h.map.view();
    lp.drop_target();
    const LocalPlanResult r = lp.plan(input(h, view, foot, s.t + 1000.0));
    EXPECT_EQ(r.set_aside_expired, 0);
    EXPECT_EQ(still_set_aside(lp, s), s.p.size());
  }

  // The robot walks toward the set-aside frontier and scans it: the map there changes, the
  // frontier flags of those nodes change (or they stop being frontiers): those entries expire.
  Eigen::Vector3f c = Eigen::Vector3f::Zero();
  for (const Eigen::Vector3f& p : s.p) c += p;
  c /= float(s.p.size());
  const Eigen::Vector3f foot2(c.x() > 0 ? c.x() - 3.f : c.x() + 3.f, 0, 0);
  h.observe(w, foot2, 40000, 2);
  const auto view = h.map.view();
  lp.drop_target();
  // 1 s later: too early for the time rule, so only the map change can expire them.
  const LocalPlanResult r = lp.plan(input(h, view, foot, s.t + 1001.0));
  EXPECT_GT(r.set_aside_expired, 0);
  EXPECT_LT(still_set_aside(lp, s), s.p.size());
  EXPECT_EQ(lp.set_aside_expired(), uint64_t(r.set_aside_expired));
  // Whatever is still set aside has the frontier flags it had when it was set aside.
  for (const SetAsideEntry& e : lp.set_aside()) {
    const auto n = h.graph.nearest(e.p_m, 0.3f, 0.5f);
    ASSERT_NE(n, storey::core::graph::kNoId);
    EXPECT_EQ(frontier_signature(h.graph.node(n)), e.frontier_sig);
  }
}

TEST(LocalPlanner, SetAsideExpiresAfterTheTimeoutOnlyOnceTheRobotMoved) {
  const World w = corridor();
  Harness h;
  const Eigen::Vector3f foot(0, 0, 0);
  h.observe(w, foot, 40000, 1);
  LocalPlanner lp(RobotModel{}, PlanOptions{}, 0.1, timed_expiry());
  const SetAside s = set_aside_one(lp, h, foot);
  ASSERT_FALSE(s.p.empty());
  const auto view = h.map.view();
  const Eigen::Vector3f moved(0, 2.5f, 0);  // 2.5 m from where the robot stood
  // Moved, but too early.
  lp.drop_target();
  EXPECT_EQ(lp.plan(input(h, view, moved, s.t + 29.0)).set_aside_expired, 0);
  EXPECT_EQ(still_set_aside(lp, s), s.p.size());
  // Late enough, but back where it stood (moved less than 2 m).
  lp.drop_target();
  EXPECT_EQ(lp.plan(input(h, view, Eigen::Vector3f(0, 1.5f, 0), s.t + 60.0)).set_aside_expired, 0);
  EXPECT_EQ(still_set_aside(lp, s), s.p.size());
  // Late enough and moved: expired (another vantage point may resolve them).
  lp.drop_target();
  const LocalPlanResult r = lp.plan(input(h, view, moved, s.t + 61.0));
  EXPECT_EQ(r.set_aside_expired, int(s.p.size()));
  EXPECT_EQ(still_set_aside(lp, s), 0u);
}

// PlanOptions::set_aside_backoff: a frontier set aside unresolved again where it was set aside
// before waits twice as long before a move away releases it (the maze's blind-ring hole drew the
// robot back every 30 s). Without the key every set-aside expires after 30 s.
TEST(LocalPlanner, SetAsideAgainAtTheSamePlaceWaitsTwiceAsLongWithBackoff) {
  const World w = corridor();
  for (const bool backoff : {false, true}) {
    SCOPED_TRACE(backoff ? "backoff" : "no backoff");
    Harness h;
    const Eigen::Vector3f foot(0, 0, 0);
    h.observe(w, foot, 40000, 1);
    PlanOptions po;
    po.set_aside_backoff = backoff;
    LocalPlanner lp(RobotModel{}, po, 0.1, timed_expiry());
    const auto view = h.map.view();
    const Eigen::Vector3f moved(2.5f, 0, 0);  // along the corridor, clear of its walls
    double t0 = 0;
    // The same frontier set aside three times: 30 s, then 60 s and 120 s with backoff.
    for (int round = 0; round < 3; ++round) {
      SCOPED_TRACE("round " + std::to_string(round));
      const SetAside s = set_aside_one(lp, h, foot, t0);
      ASSERT_FALSE(s.p.empty());
      const double expiry = backoff ? 30.0 * double(1 << round) : 30.0;
      for (const SetAsideEntry& e : lp.set_aside()) EXPECT_EQ(e.expiry_s, expiry);
      lp.drop_target();
      EXPECT_EQ(lp.plan(input(h, view, moved, s.t + expiry - 1.0)).set_aside_expired, 0);
      EXPECT_EQ(still_set_aside(lp, s), s.p.size());
      lp.drop_target();
      EXPECT_EQ(lp.plan(input(h, view, moved, s.t + expiry + 1.0)).set_aside_expired,
                int(s.p.size()));
      EXPECT_EQ(still_set_aside(lp, s), 0u);
      t0 = s.t + expiry + 2.0;
    }
  }
}

// The clusters with no node within 1.2 m (beyond track_radius_m) of cluster `id`'s nodes.
std::vector<storey::core::graph::FrontierCluster> clusters_away_from(
    const Harness& h, const std::vector<storey::core::graph::FrontierCluster>& clusters,
    int32_t id) {
  std::vector<Eigen::Vector3f> target_nodes;
  for (const auto& c : clusters)
    if (c.id == id)
      for (auto n : c.nodes) target_nodes.push_back(h.graph.node(n).p_m);
  std::vector<storey::core::graph::FrontierCluster> away;
  for (const auto& c : clusters) {
    bool near = false;
    for (auto n : c.nodes)
      for (const Eigen::Vector3f& q : target_nodes)
        near = near || (h.graph.node(n).p_m - q).head<2>().norm() <= 1.2f;
    if (!near) away.push_back(c);
  }
  return away;
}

TEST(LocalPlanner, TargetIsKeptWhenItsClusterOnlyChangedItsId) {
  const World w = corridor();
  Harness h;
  const Eigen::Vector3f foot(0, 0, 0);
  ASSERT_TRUE(scan_from(h, w, foot));
  LocalPlanner lp(RobotModel{}, PlanOptions{}, 0.1);
  const auto view = h.map.view();
  // Planned from off the scan origin, so the first viewpoint is not where the robot stands.
  LocalPlanInput in = input(h, view, Eigen::Vector3f(0, 1.5f, 0), 0.0);
  const LocalPlanResult r0 = lp.plan(in);
  ASSERT_EQ(r0.status, LocalPlanStatus::kNewTrajectory);
  const int32_t target = r0.target_cluster;
  ASSERT_GE(target, 0);

  // The same frontier under a new id (its nodes were re-clustered): the target is kept and
  // followed under the new id.
  std::vector<storey::core::graph::FrontierCluster> renamed = h.clusters.clusters();
  for (auto& c : renamed)
    if (c.id == target) c.id = 100000;
  in.clusters = &renamed;
  in.t_s = 0.5;
  const LocalPlanResult r1 = lp.plan(in);
  EXPECT_EQ(r1.status, LocalPlanStatus::kKeep) << r1.replan_reason;
  EXPECT_EQ(r1.target_cluster, 100000);

  // That frontier observed: every cluster with a node within track_radius_m (1 m) of the
  // target's nodes removed, the others left: replanned.
  const auto gone = clusters_away_from(h, renamed, 100000);
  ASSERT_FALSE(gone.empty());
  in.clusters = &gone;
  in.t_s = 1.0;
  const LocalPlanResult r2 = lp.plan(in);
  EXPECT_NE(r2.status, LocalPlanStatus::kKeep);
  EXPECT_STREQ(r2.replan_reason, "target cluster observed");
  EXPECT_NE(r2.target_cluster, 100000);
}

// PlanOptions::keep_guided_target. The guided zones' clusters (Sec. IV-C) change as the robot
// moves: the target's cluster left out of them but still among all the clusters is kept as the
// target; off, it reads as "observed" and the robot turns to another (maze seed 1, session 40:
// back and forth along a corridor for 500 s). Observed for real (gone from every list): replanned.
TEST(LocalPlanner, ATargetLeftOutOfTheGuidedClustersButStillAFrontierIsKeptWithKeepGuidedTarget) {
  const World w = corridor();
  Harness h;
  ASSERT_TRUE(scan_from(h, w, Eigen::Vector3f(0, 0, 0)));
  const auto view = h.map.view();
  const std::vector<storey::core::graph::FrontierCluster> all = h.clusters.clusters();
  for (bool keep : {false, true}) {
    PlanOptions po;
    po.keep_guided_target = keep;
    LocalPlanner lp(RobotModel{}, po, 0.1);
    LocalPlanInput in = input(h, view, Eigen::Vector3f(0, 1.5f, 0), 0.0);
    in.all_clusters = &all;
    const LocalPlanResult r0 = lp.plan(in);
    ASSERT_EQ(r0.status, LocalPlanStatus::kNewTrajectory);
    const int32_t target = r0.target_cluster;
    // The guided subset: the corridor's other end only (none near enough to the target to be
    // taken for it under a new id).
    const auto guided = clusters_away_from(h, all, target);
    ASSERT_FALSE(guided.empty());
    in.clusters = &guided;
    in.t_s = 0.5;
    const LocalPlanResult r1 = lp.plan(in);
    if (keep) {
      EXPECT_EQ(r1.status, LocalPlanStatus::kKeep) << r1.replan_reason;
      EXPECT_EQ(r1.target_cluster, target);
    } else {
      EXPECT_STREQ(r1.replan_reason, "target cluster observed");
      EXPECT_NE(r1.target_cluster, target);
      continue;
    }
    // Gone from every list: observed, whatever the key.
    in.all_clusters = &guided;
    in.t_s = 1.0;
    const LocalPlanResult r2 = lp.plan(in);
    EXPECT_STREQ(r2.replan_reason, "target cluster observed");
    EXPECT_NE(r2.target_cluster, target);
  }
}

// PlanOptions::replan_only_if_faster. A periodic replan that finds the same trajectory again (the
// robot has not moved: the same start, map and target) keeps the one followed; off, it is
// published again, and every new trajectory starts at rest (session 20: the robot slowed down at
// each periodic replan, 0.56 m/s while walking on office seed 1). A replan that arrives earlier
// (the robot walked on and a nearer viewpoint of the cluster appeared) is published either way.
LocalPlanResult periodic_replan(bool only_if_faster, bool walked) {
  const World w = corridor();
  Harness h;
  const Eigen::Vector3f foot(0, 0, 0);
  EXPECT_TRUE(scan_from(h, w, foot));
  PlanOptions po;
  po.replan_only_if_faster = only_if_faster;
  LocalPlanner lp(RobotModel{}, po, 0.1);
  const auto view = h.map.view();
  LocalPlanInput in = input(h, view, Eigen::Vector3f(0, 1.5f, 0), 0.0);
  const LocalPlanResult r0 = lp.plan(in);
  EXPECT_EQ(r0.status, LocalPlanStatus::kNewTrajectory);
  in.t_s = LocalPlannerOptions{}.replan_period_s + 0.5;
  if (walked) {  // the robot where the trajectory is by then
    const TrajectorySample on = r0.trajectory.sample(in.t_s);
    in.robot_foot_m = on.p_m;
    in.robot_velocity_mps = on.v_mps.head<2>();
    in.robot_yaw_rad = on.yaw_rad;
  }
  const LocalPlanResult r1 = lp.plan(in);
  EXPECT_EQ(r1.target_cluster, r0.target_cluster);
  if (r1.status == LocalPlanStatus::kNewTrajectory && walked) {
    EXPECT_LT(r1.trajectory.t_end(), r0.trajectory.t_end() - 1.0);  // arrives earlier
  }
  return r1;
}

TEST(LocalPlanner, APeriodicReplanKeepsTheTrajectoryFollowedUnlessTheNewOneArrivesEarlier) {
  const LocalPlanResult kept = periodic_replan(true, false);
  EXPECT_EQ(kept.status, LocalPlanStatus::kKeep) << kept.replan_reason;
  EXPECT_STREQ(kept.replan_reason, "periodic replan: the trajectory followed arrives as early");
  const LocalPlanResult again = periodic_replan(false, false);
  EXPECT_EQ(again.status, LocalPlanStatus::kNewTrajectory);
  EXPECT_STREQ(again.replan_reason, "periodic replan");
  const LocalPlanResult earlier = periodic_replan(true, true);
  EXPECT_EQ(earlier.status, LocalPlanStatus::kNewTrajectory);
  EXPECT_STREQ(earlier.replan_reason, "periodic replan");
}

// Target momentum (keep_first_in_tour): at a periodic replan the tour re-solved from a little
// further on may start at another cluster for a metre or two less; the current target stays
// first unless the other tour is shorter by max(margin_m, margin_frac * tour).
TEST(LocalPlanner, PeriodicReplanKeepsTheTargetUnlessAnotherTourIsClearlyShorter) {
  // The robot (0) between two corridor ends A (1) and B (2), 16 m apart.
  auto costs = [](double to_a, double to_b) {
    return std::vector<double>{0, to_a, to_b, to_a, 0, 16, to_b, 16, 0};
  };
  // B first is 1 m shorter (23 vs 24): A, the current target, stays first.
  std::vector<size_t> order{1, 0};  // indices into the tour's clusters: B then A
  keep_first_in_tour(0, costs(8, 7), 3, false, 2.0, 0.1, order);
  EXPECT_EQ(order, (std::vector<size_t>{0, 1}));
  // B first is 10 m shorter (19 vs 29): B stays first.
  order = {1, 0};
  keep_first_in_tour(0, costs(13, 3), 3, false, 2.0, 0.1, order);
  EXPECT_EQ(order, (std::vector<size_t>{1, 0}));
  // The fraction widens the margin on long tours: 3 m on a 40 m tour is kept (10 % = 4 m).
  order = {1, 0};
  keep_first_in_tour(0, costs(27, 24), 3, false, 2.0, 0.1, order);
  EXPECT_EQ(order, (std::vector<size_t>{0, 1}));
  // With an end anchor (a zone prior, matrix index n - 1) its leg counts: A first ends 20 m
  // from the anchor instead of 1 m, 20 m longer: B stays first.
  std::vector<double> c4{0, 8, 7, 30, 8, 0, 16, 1, 7, 16, 0, 20, 30, 1, 20, 0};
  order = {1, 0};
  keep_first_in_tour(0, c4, 4, true, 2.0, 0.1, order);
  EXPECT_EQ(order, (std::vector<size_t>{1, 0}));
  // Already first, or not in the tour: unchanged.
  order = {0, 1};
  keep_first_in_tour(0, costs(30, 1), 3, false, 2.0, 0.1, order);
  EXPECT_EQ(order, (std::vector<size_t>{0, 1}));
  order = {1};
  keep_first_in_tour(0, costs(1, 30), 3, false, 2.0, 0.1, order);
  EXPECT_EQ(order, (std::vector<size_t>{1}));
}

// Path-failure retry (PlanOptions::path_retries). Stage 3 plans on the map, Stage 1 on the graph:
// here the map has a wall across the corridor 2 m east of the robot that the graph (built
// before it stood) does not know, so every trajectory to the frontier at the east end fails and
// the frontier is set aside for a path failure. Off, that ends the search (kNoReachableTarget)
// where the robot stands. On, the robot first walks to a vantage point at least retry_move_m
// away (west: east is walled off), the set-aside is released when the walk ends and Stage 3
// tries again from there, at most path_retries times for that frontier before the search ends.
namespace {
struct RetryRun {
  int retries = 0;          // retry walks
  int other_moves = 0;      // any other new trajectory
  double min_walk_m = 1e9;  // shortest retry walk
  bool released = true;     // every retry walk's end released the set-aside nodes
  LocalPlanStatus last = LocalPlanStatus::kBadInput;
  size_t set_aside = 0;  // set-aside nodes at the end
};

RetryRun run_walled_off(int path_retries) {
  const World w = corridor();
  World walled = w;
  walled.add({2.0f, -3, 0}, {2.3f, 3, 2.5f});
  Harness h, hw;
  Eigen::Vector3f foot(0, 0, 0);
  h.observe(w, foot, 40000, 1);
  hw.observe(walled, foot, 40000, 1);
  PlanOptions po;
  po.path_retries = path_retries;
  LocalPlannerOptions lo;
  lo.set_aside_expiry_s = 1e6;  // only the retry releases them here
  LocalPlanner lp(RobotModel{}, po, 0.1, lo);
  std::vector<storey::core::graph::FrontierCluster> east;
  for (const auto& c : h.clusters.clusters())
    if (c.centroid_m.x() > 5.0f) east.push_back(c);
  EXPECT_FALSE(east.empty());
  const auto view = hw.map.view();
  RetryRun run;
  double yaw = 0, t = 0;
  int idle = 0;
  for (int cycle = 0; cycle < 200 && idle < 12; ++cycle) {
    LocalPlanInput in = input(h, view, foot, t);
    in.clusters = &east;
    in.robot_yaw_rad = yaw;
    in.last_resort = true;
    const size_t before = lp.set_aside().size();
    const LocalPlanResult r = lp.plan(in);
    run.last = r.status;
    if (r.status != LocalPlanStatus::kNewTrajectory) {
      idle += r.status == LocalPlanStatus::kNoReachableTarget;
      t += 1.0;
      continue;
    }
    idle = 0;
    if (std::string(r.replan_reason).rfind("retry", 0) != 0) {
      ++run.other_moves;
      break;
    }
    ++run.retries;
    EXPECT_GT(before, 0u);
    const auto end = r.trajectory.pose(r.trajectory.t_end());
    run.min_walk_m =
        std::min(run.min_walk_m, double((end.foot_m.cast<float>() - foot).head<2>().norm()));
    // Walked to its end: the next cycle releases the set-aside nodes (and fails again).
    foot = end.foot_m.cast<float>();
    yaw = end.yaw_rad;
    t = r.trajectory.t_end() + 0.1;
    LocalPlanInput at_end = input(h, view, foot, t);
    at_end.clusters = &east;
    at_end.robot_yaw_rad = yaw;
    at_end.last_resort = true;
    lp.plan(at_end);
    run.released = run.released && lp.set_aside_expired() > 0;
    t += 1.0;
  }
  run.set_aside = lp.set_aside().size();
  return run;
}
}  // namespace

TEST(LocalPlanner, PathFailuresAreRetriedFromANewVantagePointBeforeTheSearchEnds) {
  const RetryRun off = run_walled_off(0);
  EXPECT_EQ(off.retries, 0);
  EXPECT_EQ(off.other_moves, 0);
  EXPECT_EQ(off.last, LocalPlanStatus::kNoReachableTarget);
  EXPECT_GT(off.set_aside, 0u);
  for (int n : {1, 2}) {
    const RetryRun on = run_walled_off(n);
    EXPECT_EQ(on.retries, n);  // bounded: path_retries walks for the one frontier
    EXPECT_EQ(on.other_moves, 0);
    EXPECT_GE(on.min_walk_m, 2.0 - 0.3);  // retry_move_m, less the trajectory's end tolerance
    EXPECT_TRUE(on.released);
    EXPECT_EQ(on.last, LocalPlanStatus::kNoReachableTarget);
    EXPECT_GT(on.set_aside, 0u);
  }
}

// PlanOptions::flight_foot: a frontier beside a flight's foot (the treads above the sensor are
// edge-on from the floor) whose viewpoint was reached and that stays a frontier is not set aside:
// the robot is sent to the flight's foot (on its axis, facing up, before the first riser; here
// as close as C_reach reaches, 1.4 m) and from there climbs blind. Without the switch the same
// frontier is never sent there.
namespace {
World flight_room() {
  World w;
  w.add({-4, -3, -0.2f}, {6, 3, 0});
  w.stairs(0.0f, -0.6f, 0.6f, 0.0f, 12, 0.15f, 0.30f);
  w.add({0, -0.72f, 0}, {3.6f, -0.6f, 2.5f});
  w.add({0, 0.6f, 0}, {3.6f, 0.72f, 2.5f});
  w.add({-4, -3.2f, 0}, {6, -3, 2.5f});  // the room's walls
  w.add({-4, 3, 0}, {6, 3.2f, 2.5f});
  w.add({-4.2f, -3, 0}, {-4, 3, 2.5f});
  return w;
}

// The frontier clusters at the foot of a flight rising from x = 0 (floor-level nodes within
// 1.2 m of (-0.4, 0)).
std::vector<storey::core::graph::FrontierCluster> clusters_at_foot(const Harness& h) {
  std::vector<storey::core::graph::FrontierCluster> at_foot;
  for (const auto& c : h.clusters.clusters())
    for (storey::core::graph::NodeId n : c.nodes) {
      const Eigen::Vector3f p = h.graph.node(n).p_m;
      if (p.z() < 0.1f && (p - Eigen::Vector3f(-0.4f, 0, 0)).head<2>().norm() < 1.2f) {
        at_foot.push_back(c);
        break;
      }
    }
  return at_foot;
}

// One planning cycle on `clusters` (last resort allowed), the robot at foot / yaw at time t. A new
// trajectory is walked to its end (foot, yaw there; t 1.5 s after its end; the map is not
// rescanned) and returned; else t moves on 1 s.
std::optional<LocalPlanResult> walked_cycle(
    LocalPlanner& lp, const Harness& h, const storey::core::map::MapView& view,
    const std::vector<storey::core::graph::FrontierCluster>& clusters, Eigen::Vector3f& foot,
    double& yaw, double& t) {
  LocalPlanInput in = input(h, view, foot, t);
  in.clusters = &clusters;
  in.robot_yaw_rad = yaw;
  in.last_resort = true;
  LocalPlanResult r = lp.plan(in);
  if (r.status != LocalPlanStatus::kNewTrajectory) {
    t += 1.0;
    return std::nullopt;
  }
  const auto end = r.trajectory.pose(r.trajectory.t_end());
  foot = end.foot_m.cast<float>();
  yaw = end.yaw_rad;
  t = r.trajectory.t_end() + 1.5;
  return r;
}

// The blind climb and the climbs from a flight's foot (on in config/default.yaml).
PlanOptions climbing_options() {
  PlanOptions po;
  po.climb_blind = true;
  po.flight_foot = true;
  return po;
}

// flight_room() seen from two places on the floor beside the flight.
void observe_flight_room(Harness& h) {
  const World w = flight_room();
  h.observe(w, {-2.0f, 1.2f, 0}, 40000, 1);
  h.observe(w, {-1.5f, -1.5f, 0}, 40000, 2);
}

// flight_room() observed; its frontier clusters at the flight's foot.
std::vector<storey::core::graph::FrontierCluster> flight_room_at_foot(Harness& h) {
  observe_flight_room(h);
  return clusters_at_foot(h);
}

struct FootRun {
  bool to_foot = false;  // a new trajectory with the flight's-foot reason
  Eigen::Vector3d foot_m = Eigen::Vector3d::Zero();
  double foot_yaw = 0;
  Eigen::Vector3d walk_end_m = Eigen::Vector3d::Zero();  // where the trajectory to the foot ends
  bool climbed = false;  // then a climb ending more than three treads up
};

// `after`, if given, sees the planner after one more cycle once the loop has ended.
FootRun run_flight_foot(bool on, PlanOptions po = {},
                        const std::function<void(const LocalPlanner&)>& after = {}) {
  Harness h;
  observe_flight_room(h);
  po.climb_blind = true;
  po.flight_foot = on;
  const auto view = h.map.view();
  LocalPlanner lp(RobotModel{}, po, 0.1);
  Eigen::Vector3f foot(-2.0f, 1.2f, 0);
  double yaw = 0, t = 0;
  FootRun run;
  const std::vector<storey::core::graph::FrontierCluster> at_foot = clusters_at_foot(h);
  EXPECT_FALSE(at_foot.empty());
  for (int cycle = 0; cycle < 12 && !run.climbed; ++cycle) {
    const auto r = walked_cycle(lp, h, view, at_foot, foot, yaw, t);
    if (!r) continue;
    const std::string reason = r->replan_reason;
    if (reason.rfind("to a flight's foot", 0) == 0) {
      run.to_foot = true;
      run.foot_m = r->target_m;
      run.foot_yaw = r->target_yaw_rad;
      run.walk_end_m = r->trajectory.pose(r->trajectory.t_end()).foot_m;
    }
    if (reason.rfind("climb on", 0) == 0 && foot.z() > 0.5f) run.climbed = true;
  }
  if (after) {  // one more cycle: the climb's end is recorded at the first plan after it
    walked_cycle(lp, h, view, at_foot, foot, yaw, t);
    after(lp);
  }
  return run;
}
}  // namespace

// PlanOptions::no_views_on_climbed_flights: once the flight is climbed, a viewpoint on it (here
// on its third tread, on its axis) is no target; one on the floor beside it still is.
TEST(LocalPlanner, AViewpointOnAFlightClimbedIsNoTargetWithNoViewsOnClimbedFlights) {
  for (const bool on : {false, true}) {
    PlanOptions po;
    po.no_views_on_climbed_flights = on;
    bool checked = false;
    const FootRun run = run_flight_foot(true, po, [&](const LocalPlanner& lp) {
      checked = true;
      EXPECT_EQ(lp.view_allowed(Eigen::Vector3f(0.75f, 0, 0.45f)), !on);
      EXPECT_TRUE(lp.view_allowed(Eigen::Vector3f(-2.0f, 2.0f, 0)));
    });
    ASSERT_TRUE(run.climbed);
    EXPECT_TRUE(checked);
  }
}

TEST(LocalPlanner, AFrontierBesideAFlightSendsTheRobotToTheFlightsFootToClimb) {
  const FootRun on = run_flight_foot(true);
  ASSERT_TRUE(on.to_foot);
  EXPECT_NEAR(on.foot_m.y(), 0.0, 0.15) << on.foot_m.transpose();  // on the axis
  EXPECT_GE(on.foot_m.x(), -1.5) << on.foot_m.transpose();         // before the first riser
  EXPECT_LE(on.foot_m.x(), -0.4) << on.foot_m.transpose();
  EXPECT_NEAR(on.foot_yaw, 0.0, 0.15);  // facing up the flight
  // The walk ends on the flight's axis, not within the voxel search's goal tolerance of the foot.
  EXPECT_NEAR(on.walk_end_m.y(), on.foot_m.y(), 0.05)
      << on.walk_end_m.transpose() << " vs " << on.foot_m.transpose();
  EXPECT_TRUE(on.climbed);
  EXPECT_FALSE(run_flight_foot(false).to_foot);
}

namespace {
// The robot sent to the foot of h's flight (flight_foot on) from (-2, 1.2): the trip's result,
// then plan cycles with every frontier gone (`none`, as when it is seen on the way).
struct FootTrip {
  const Harness& h;
  storey::core::map::MapView view;
  LocalPlanner lp;
  Eigen::Vector3f foot{-2.0f, 1.2f, 0};
  double yaw = 0, t = 0;
  std::vector<storey::core::graph::FrontierCluster> none;

  explicit FootTrip(const Harness& harness)
      : h(harness), view(harness.map.view()), lp(RobotModel{}, foot_options(), 0.1) {}
  static PlanOptions foot_options() {
    PlanOptions po;
    po.climb_blind = po.flight_foot = true;
    return po;
  }
  // Plan cycles over the foot's clusters until the trip to the foot is planned (walked to its end).
  std::optional<LocalPlanResult> to_foot() {
    const std::vector<storey::core::graph::FrontierCluster> at_foot = clusters_at_foot(h);
    EXPECT_FALSE(at_foot.empty());
    for (int cycle = 0; cycle < 12; ++cycle)
      if (auto r = walked_cycle(lp, h, view, at_foot, foot, yaw, t);
          r && std::string(r->replan_reason).rfind("to a flight's foot", 0) == 0)
        return r;
    return std::nullopt;
  }
  // One cycle with no frontier left, the robot at p / yaw_p at time t_p.
  LocalPlanResult without_frontiers(const Eigen::Vector3f& p, double yaw_p, double t_p) {
    LocalPlanInput in = input(h, view, p, t_p);
    in.clusters = &none;
    in.robot_yaw_rad = yaw_p;
    in.last_resort = true;
    return lp.plan(in);
  }
  // At the foot with no frontier left: a climb, ending higher than min_z_m.
  void expect_climb_at_foot(double min_z_m) {
    const LocalPlanResult climb = without_frontiers(foot, yaw, t);
    ASSERT_EQ(climb.status, LocalPlanStatus::kNewTrajectory);
    EXPECT_EQ(std::string(climb.replan_reason).rfind("climb on", 0), 0u) << climb.replan_reason;
    EXPECT_GT(climb.trajectory.pose(climb.trajectory.t_end()).foot_m.z(), min_z_m);
  }
};
}  // namespace

// An open flight (treads without risers): from its foot the floor under the flight shows between
// the treads, right past the last tread seen. That is not a landing's edge but treads not seen
// yet: the climb goes up to the last support seen (a partial climb) instead of being dropped
// (teaching_building seed 1, session 22: every climb from a foot ended there).
TEST(LocalPlanner, FromTheFootOfAnOpenFlightTheClimbGoesUpToTheLastTreadSeen) {
  World w;
  w.add({-4, -3, -0.2f}, {6, 3, 0});  // the floor, also under the flight
  for (int i = 0; i < 12; ++i)        // 4 cm treads, open risers
    w.add({0.3f * float(i), -0.6f, 0.15f * float(i + 1) - 0.04f},
          {0.3f * float(i + 1), 0.6f, 0.15f * float(i + 1)});
  w.add({0, -0.72f, 0}, {3.6f, -0.6f, 2.5f});
  w.add({0, 0.6f, 0}, {3.6f, 0.72f, 2.5f});
  w.add({-4, -3.2f, 0}, {6, -3, 2.5f});  // the room's walls
  w.add({-4, 3, 0}, {6, 3.2f, 2.5f});
  w.add({-4.2f, -3, 0}, {-4, 3, 2.5f});
  Harness h;
  h.observe(w, {-2.0f, 1.2f, 0}, 40000, 1);
  h.observe(w, {-1.5f, -1.5f, 0}, 40000, 2);
  FootTrip trip(h);
  ASSERT_TRUE(trip.to_foot());
  trip.expect_climb_at_foot(0.25);
}

// The frontier beside a flight is often seen on the way to its foot: the robot walks on to the
// foot even so, and climbs from there (teaching_building seed 1, session 22: trips to a flight's
// foot were dropped as "target cluster observed" within 2.5 s, each foot is tried once, and the
// upper floor was never reached).
TEST(LocalPlanner, AFlightsFootIsWalkedToAndClimbedFromAfterItsFrontierWasSeen) {
  Harness h;
  observe_flight_room(h);
  FootTrip trip(h);
  const std::optional<LocalPlanResult> to_foot = trip.to_foot();
  ASSERT_TRUE(to_foot);
  // Half way there the cluster is gone: the trip goes on.
  const BsplineTrajectory& tr = to_foot->trajectory;
  const double t_mid = 0.5 * (tr.t_start() + tr.t_end());
  EXPECT_EQ(
      trip.without_frontiers(tr.pose(t_mid).foot_m.cast<float>(), tr.pose(t_mid).yaw_rad, t_mid)
          .status,
      LocalPlanStatus::kKeep);
  // At the foot: up the flight (no other frontier left on this floor: climbed at once).
  trip.expect_climb_at_foot(0.5);
}

// Just after a climb the new floor's graph is still growing: no target then is not the end of
// the search but kSettling, for climb_settle_s (teaching_building seed 3, session 39: "complete"
// 5 s after a climb onto a U-shaped stair's landing, the floor above never explored).
TEST(LocalPlanner, NoTargetJustAfterAClimbIsSettlingNotTheEnd) {
  Harness h;
  observe_flight_room(h);
  FootTrip trip(h);
  ASSERT_TRUE(trip.to_foot());
  const double settle_s = LocalPlannerOptions{}.climb_settle_s;
  double climb_end = -1;
  int settling = 0, ended = 0;
  for (int cycle = 0; cycle < 40 && ended == 0; ++cycle) {
    const LocalPlanResult r = trip.without_frontiers(trip.foot, trip.yaw, trip.t);
    if (r.status == LocalPlanStatus::kNewTrajectory) {
      const auto end = r.trajectory.pose(r.trajectory.t_end());
      trip.foot = end.foot_m.cast<float>();
      trip.yaw = end.yaw_rad;
      trip.t = r.trajectory.t_end() + 0.5;
      if (std::string(r.replan_reason).rfind("climb on", 0) == 0) climb_end = r.trajectory.t_end();
      continue;
    }
    ASSERT_GE(climb_end, 0) << "no climb before " << to_string(r.status);
    // The climb's end is recorded at the first plan after it (0.5 s later).
    if (trip.t - climb_end < settle_s) {
      EXPECT_EQ(r.status, LocalPlanStatus::kSettling) << to_string(r.status) << " at " << trip.t;
      ++settling;
    } else if (trip.t - climb_end > settle_s + 1.0) {
      EXPECT_EQ(r.status, LocalPlanStatus::kNoFrontiers) << to_string(r.status) << " at " << trip.t;
      ++ended;
    }
    trip.t += 1.0;
  }
  EXPECT_GT(trip.foot.z(), 0.5f);
  EXPECT_GT(settling, 5);
  EXPECT_EQ(ended, 1);
}

// LocalPlanInput::trajectory_lag_s: the control task's reference waits for the robot (a turn
// onto the trajectory, a safety stop), so a climb's planned end can pass on the clock with the
// robot still on the flight. Judged "done" then, the climb stopped 0.7 m short of its landing and
// the robot turned back down (house seed 1 with a re-timed, faster trajectory, session 21). On
// the trajectory's own clock it is still under way.
TEST(LocalPlanner, AClimbWhoseReferenceTrailsTheClockIsNotDoneAtItsPlannedEnd) {
  Harness h;
  const auto at_foot = flight_room_at_foot(h);
  ASSERT_FALSE(at_foot.empty());
  const auto view = h.map.view();
  // lag: the reported lag; past: the clock past the planned end.
  struct Case {
    double lag, past;
    bool kept;
  };
  for (const Case c : {Case{0.0, 0.5, false}, Case{2.5, 0.5, true},
                       // A robot that cannot follow (the reference waits for ever): still done
                       // once the clock is kMaxReferenceLagS past the planned end.
                       Case{30.0, LocalPlanner::kMaxReferenceLagS - 1.0, true},
                       Case{30.0, LocalPlanner::kMaxReferenceLagS + 1.0, false}}) {
    SCOPED_TRACE(::testing::Message() << "lag " << c.lag << " s, " << c.past << " s past the end");
    LocalPlanner lp(RobotModel{}, climbing_options(), 0.1);
    Eigen::Vector3f foot(-2.0f, 1.2f, 0);
    double yaw = 0, t = 0;
    BsplineTrajectory climb;
    for (int cycle = 0; cycle < 12 && climb.empty(); ++cycle) {
      LocalPlanInput in = input(h, view, foot, t);
      in.clusters = &at_foot;
      in.robot_yaw_rad = yaw;
      in.last_resort = true;
      const LocalPlanResult r = lp.plan(in);
      if (r.status != LocalPlanStatus::kNewTrajectory) {
        t += 1.0;
        continue;
      }
      if (std::string(r.replan_reason).rfind("climb on", 0) == 0) {
        climb = r.trajectory;
        break;
      }
      const auto end = r.trajectory.pose(r.trajectory.t_end());  // walked to its end
      foot = end.foot_m.cast<float>();
      yaw = end.yaw_rad;
      t = r.trajectory.t_end() + 1.5;
    }
    ASSERT_FALSE(climb.empty());
    ASSERT_TRUE(lp.committed());
    // Past the planned end, the robot where the reference stands 2.5 s earlier.
    const BodyPose on = climb.pose(climb.t_end() - 2.5);
    ASSERT_GT(on.foot_m.z(), 0.3) << "on the flight";
    LocalPlanInput in = input(h, view, on.foot_m.cast<float>(), climb.t_end() + c.past);
    in.clusters = &at_foot;
    in.robot_yaw_rad = on.yaw_rad;
    in.trajectory_lag_s = c.lag;
    const LocalPlanResult r = lp.plan(in);
    if (c.kept) {
      EXPECT_EQ(r.status, LocalPlanStatus::kKeep) << r.replan_reason;
      EXPECT_TRUE(lp.committed());
    } else {
      EXPECT_NE(r.status, LocalPlanStatus::kKeep);
      EXPECT_STREQ(r.replan_reason, "escape or climb done");
      EXPECT_FALSE(lp.committed());
    }
  }
}

// A climb that ends higher than planned (it took a tread for its landing: the treads past it
// unseen, the body's space over it seen free) leaves the robot at the real landing's edge, the
// walk onto it still to come: recorded as a partial climb ending where the robot stands, so
// that climbing goes on from there (office seed 3 with graph.close_probes_at_wall_faces, session
// 25: 0.2 m over the planned end, nothing grew there, "complete"). Here a partial climb up
// flight_room's flight, its robot reported at the planned end or 0.2 m over it.
TEST(LocalPlanner, AClimbThatEndsHigherThanPlannedIsAPartialClimbEndingThere) {
  Harness h;
  const auto at_foot = flight_room_at_foot(h);
  ASSERT_FALSE(at_foot.empty());
  const auto view = h.map.view();
  for (const double above : {0.0, 0.2}) {
    SCOPED_TRACE(::testing::Message() << "the robot " << above << " m over the planned end");
    LocalPlanner lp(RobotModel{}, climbing_options(), 0.1);
    Eigen::Vector3f foot(-2.0f, 1.2f, 0);
    double yaw = 0, t = 0;
    BsplineTrajectory climb;
    for (int cycle = 0; cycle < 12 && climb.empty(); ++cycle) {
      const auto r = walked_cycle(lp, h, view, at_foot, foot, yaw, t);
      if (r && std::string(r->replan_reason).rfind("climb on", 0) == 0) climb = r->trajectory;
    }
    ASSERT_FALSE(climb.empty());
    const BodyPose end = climb.pose(climb.t_end());
    const Eigen::Vector3d stand = end.foot_m + Eigen::Vector3d(0, 0, above);
    LocalPlanInput in = input(h, view, stand.cast<float>(), climb.t_end() + 0.5);
    in.clusters = &at_foot;
    in.robot_yaw_rad = end.yaw_rad;
    lp.plan(in);
    // At the planned end the climb's own end serves; 0.2 m over it (more than a step's
    // tolerance) only the end recorded where the robot stands.
    EXPECT_TRUE(lp.at_partial_climb_end(stand)) << stand.transpose();
  }
}

// A partial climb (nothing seen past the top tread from below) ends on the top tread. There the
// body pitches up with the flight: every ray passes over the landing's body space, which is never
// seen at body height (office seed 1, session 15: no node grew on the landing and the run ended
// "complete"). With flight_foot, at a partial climb's end the landing counts as seen where rays
// crossed up to 0.6 m over the body: the robot walks on onto it. Nothing observed there: it stays.
namespace {
World flight_to_landing() {
  World w;
  w.add({-4, -3, -0.2f}, {6, 3, 0});
  w.stairs(0.0f, -0.6f, 0.6f, 0.0f, 7, 0.15f, 0.30f);   // up to 1.05 m at x 2.1
  w.add({2.1f, -0.72f, -0.2f}, {3.35f, 0.72f, 1.05f});  // the landing, level with the top tread
  w.add({3.35f, -0.87f, 0}, {3.5f, 0.87f, 4.5f});       // its wall
  w.add({0, -0.87f, 0}, {3.35f, -0.6f, 4.5f});          // the stairwell's sides
  w.add({0, 0.6f, 0}, {3.35f, 0.87f, 4.5f});
  w.add({-4, -3.2f, 0}, {6, -3, 4.5f});  // the room's walls and ceiling
  w.add({-4, 3, 0}, {6, 3.2f, 4.5f});
  w.add({-4.2f, -3, 0}, {-4, 3, 4.5f});
  w.add({-4, -3, 4.3f}, {6, 3, 4.5f});
  return w;
}
}  // namespace

TEST(LocalPlanner, APartialClimbsEndOnTheTopTreadWalksOnOntoALandingSeenOnlyFromAbove) {
  Harness h;
  const World w = flight_to_landing();
  // From the floor, returns only up to the top tread's end: no ray crosses the landing.
  for (const Eigen::Vector3f& f :
       {Eigen::Vector3f(-2.0f, 1.2f, 0), Eigen::Vector3f(-1.5f, -1.5f, 0)}) {
    std::vector<Eigen::Vector3f> pts;
    const Eigen::Vector3f s = f + Eigen::Vector3f(0, 0, 0.5f);
    for (const Eigen::Vector3f& p : storey::test::macro::scan(w, s, 40000, f.x() < -1.8f ? 1 : 2))
      if (p.x() < 2.05f) pts.push_back(p);
    h.insert(s, pts, f);
  }
  PlanOptions po;
  po.climb_blind = true;
  po.flight_foot = true;
  LocalPlanner lp(RobotModel{}, po, 0.1);
  Eigen::Vector3f foot(-2.0f, 1.2f, 0);
  double yaw = 0, t = 0;
  // The frontier at the flight's foot (the floor before the first riser, unseen). Clusters that
  // reach onto the flight are left out: with them the climb is left for last and the robot is
  // first sent to their nodes on that unseen floor, which this static map never shows it.
  std::vector<storey::core::graph::FrontierCluster> at_foot = clusters_at_foot(h);
  std::erase_if(at_foot, [&](const storey::core::graph::FrontierCluster& c) {
    return std::any_of(c.nodes.begin(), c.nodes.end(), [&](storey::core::graph::NodeId n) {
      return h.graph.node(n).p_m.z() > 0.1f;
    });
  });
  ASSERT_FALSE(at_foot.empty());
  // Plans `cycles` times; the robot walks each trajectory to its end. Returns the last "climb on"
  // trajectory's end (NaN: none).
  auto run = [&](const storey::core::map::MapView& view, int cycles) {
    Eigen::Vector3d last(NAN, NAN, NAN);
    for (int cycle = 0; cycle < cycles; ++cycle) {
      const auto r = walked_cycle(lp, h, view, at_foot, foot, yaw, t);
      if (r && std::string(r->replan_reason).rfind("climb on", 0) == 0) last = foot.cast<double>();
    }
    return last;
  };
  {
    const auto view = h.map.view();
    const Eigen::Vector3d top = run(view, 12);
    ASSERT_TRUE(top.allFinite());
    EXPECT_NEAR(top.z(), 1.05, 0.06) << top.transpose();  // partial: on the top tread
    EXPECT_LE(top.x(), 2.1) << top.transpose();
    // Nothing observed over the landing: no walk onto it.
    EXPECT_FALSE(run(view, 4).allFinite());
    EXPECT_EQ(lp.landings(), 0u) << "a partial climb ends on the top tread, not on a landing";
  }
  // The pitched body's scan from the top tread: rays 12-42 deg up only.
  h.observe(w, foot, 40000, 4, 0.21f, 0.73f);
  const auto view = h.map.view();
  const Eigen::Vector3d on = run(view, 4);
  ASSERT_TRUE(on.allFinite());
  EXPECT_NEAR(on.z(), 1.05, 0.06) << on.transpose();
  EXPECT_GE(on.x(), 2.1 + 0.2) << on.transpose();   // on the landing
  EXPECT_LE(on.x(), 3.35 - 0.3) << on.transpose();  // the body short of its wall
  // Once that walk has ended, the robot stands on the landing: the firmware enters its ground.
  run(view, 1);
  EXPECT_EQ(lp.landings(), 1u);
}

// PlanOptions::no_progress_s: a robot that does not move while it has a target (its body meets
// something the plan did not expect: office seed 1, session 15, 255 s against a table leg, every
// replan the same) gets its target set aside and steps away, once per no_progress_s. Never while
// it moves, never with the switch at 0.
namespace {
struct StuckRun {
  uint64_t events = 0;
  bool escaped = false;  // a trajectory with the no-progress escape's reason
  size_t set_aside = 0;  // set-aside entries for kOverdue
};
StuckRun run_stuck(double no_progress_s, bool walk) {
  const World w = corridor();
  Harness h;
  EXPECT_TRUE(scan_from(h, w, Eigen::Vector3f::Zero()));
  PlanOptions po;
  po.no_progress_s = no_progress_s;
  LocalPlanner lp(RobotModel{}, po, 0.1);
  const auto view = h.map.view();
  StuckRun run;
  BsplineTrajectory traj;
  Eigen::Vector3d foot(0, 1.5, 0);
  double yaw = 0;
  for (double t = 0; t <= 25.0; t += 0.5) {
    if (walk && !traj.empty()) {  // the robot on its reference
      const auto p = traj.pose(std::clamp(t, traj.t_start(), traj.t_end()));
      foot = p.foot_m, yaw = p.yaw_rad;
    }
    LocalPlanInput in = input(h, view, foot.cast<float>(), t);
    in.robot_yaw_rad = yaw;
    const LocalPlanResult r = lp.plan(in);
    if (r.status != LocalPlanStatus::kNewTrajectory) continue;
    traj = r.trajectory;
    run.escaped |= std::string(r.replan_reason).rfind("escape: no progress", 0) == 0;
  }
  run.events = lp.no_progress_events();
  for (const SetAsideEntry& e : lp.set_aside())
    run.set_aside += e.reason == SetAsideReason::kOverdue;
  return run;
}
}  // namespace

TEST(LocalPlanner, ARobotThatDoesNotMoveWithATargetSetsItAsideAndStepsAway) {
  const StuckRun stuck = run_stuck(10.0, false);
  EXPECT_EQ(stuck.events, 2u);  // at 10 s and 20 s
  EXPECT_TRUE(stuck.escaped);
  EXPECT_GT(stuck.set_aside, 0u);
  const StuckRun off = run_stuck(0.0, false);
  EXPECT_EQ(off.events, 0u);
  EXPECT_FALSE(off.escaped);
  const StuckRun walking = run_stuck(10.0, true);
  EXPECT_EQ(walking.events, 0u);
  EXPECT_FALSE(walking.escaped);
}

// Boxed in on a flight: in a stairwell too narrow for the body to turn in, facing up, with the
// only frontiers on the floor below, every Stage 3 trajectory hits the side walls next to the
// start. Before, each frontier was set aside in turn until "complete" (office seed 4, session
// 15); with climb_blind the robot walks straight down the flight's axis (backwards) to the floor.
namespace {
World narrow_flight() {
  World w;
  w.add({-6, -3, -0.2f}, {6, 3, 0});
  w.stairs(0.0f, -0.5f, 0.5f, 0.0f, 12, 0.15f, 0.30f);  // up to 1.8 m at x 3.6
  w.add({3.6f, -0.5f, -0.2f}, {5.0f, 0.5f, 1.8f});      // the landing
  w.add({0, -0.7f, 0}, {5.0f, -0.5f, 3.5f});            // the stairwell, 1 m wide
  w.add({0, 0.5f, 0}, {5.0f, 0.7f, 3.5f});
  w.add({5.0f, -0.6f, 0}, {5.2f, 0.6f, 3.5f});
  return w;
}
}  // namespace

namespace {
// The frontier clusters whose nodes all lie on the floor (z < 0.1 m).
std::vector<storey::core::graph::FrontierCluster> floor_clusters(const Harness& h) {
  std::vector<storey::core::graph::FrontierCluster> below;
  for (const auto& c : h.clusters.clusters())
    if (std::all_of(c.nodes.begin(), c.nodes.end(),
                    [&](auto n) { return h.graph.node(n).p_m.z() < 0.1f; }))
      below.push_back(c);
  return below;
}
}  // namespace

TEST(LocalPlanner, BoxedInOnAFlightWalksStraightDownItsAxisToTheFloor) {
  Harness h;
  const World w = narrow_flight();
  h.observe(w, {-2.0f, 0, 0}, 40000, 1);
  h.observe(w, {-1.0f, 1.5f, 0}, 40000, 2);
  const Eigen::Vector3f on(2.25f, 0, 1.2f);  // tread 8, facing up
  h.observe(w, on, 40000, 3);
  const std::vector<storey::core::graph::FrontierCluster> below = floor_clusters(h);
  ASSERT_FALSE(below.empty());
  PlanOptions po;
  po.climb_blind = true;
  LocalPlanner lp(RobotModel{}, po, 0.1);
  const auto view = h.map.view();
  Eigen::Vector3d foot = on.cast<double>();
  double yaw = 0, t = 0;
  bool descended = false;
  for (int cycle = 0; cycle < 12 && !descended; ++cycle) {
    LocalPlanInput in = input(h, view, foot.cast<float>(), t);
    in.clusters = &below;
    in.robot_yaw_rad = yaw;
    const LocalPlanResult r = lp.plan(in);
    t += 0.5;
    if (r.status != LocalPlanStatus::kNewTrajectory) continue;
    const auto end = r.trajectory.pose(r.trajectory.t_end());
    if (std::string(r.replan_reason).rfind("descend", 0) == 0) {
      descended = true;
      EXPECT_LT(end.foot_m.z(), 0.05) << end.foot_m.transpose();  // on the floor
      EXPECT_LT(end.foot_m.x(), -0.2) << end.foot_m.transpose();  // past the flight's foot
      EXPECT_NEAR(std::abs(end.foot_m.y()), 0.0, 0.15);           // along its axis
      EXPECT_NEAR(std::abs(std::remainder(end.yaw_rad, 2 * M_PI)), 0.0, 0.2);  // backwards
    }
    foot = end.foot_m, yaw = end.yaw_rad;
    t = r.trajectory.t_end() + 0.5;
  }
  EXPECT_TRUE(descended);
}

// On a flight where every trajectory down hits the stairwell and no descent is left (two walked
// already, the robot came back up for a frontier on the flight), the climb the planner finds is
// taken: up is the way on. Before, it was deferred (other frontiers first) and the frontiers
// below were set aside one by one until "complete" (teaching_building seed 3, session 39: mid-way
// up a U-shaped stair's first flight, the floor above never explored). The scans leave out the
// LiDAR's blind ring (no return within 0.7 m of the sensor, 1.2 m on the flight).
TEST(LocalPlanner, OnAFlightWithNoWayDownLeftTheRobotClimbsOnInsteadOfSettingTheFloorAside) {
  Harness h;
  const World w = narrow_flight();
  auto look = [&](const Eigen::Vector3f& f, uint32_t seed, float ring) {
    const Eigen::Vector3f s = f + Eigen::Vector3f(0, 0, 0.5f);
    std::vector<Eigen::Vector3f> pts;
    for (const Eigen::Vector3f& p : storey::test::macro::scan(w, s, 40000, seed))
      if ((p - s).head<2>().norm() > ring) pts.push_back(p);
    h.insert(s, pts, f);
  };
  look({-2.0f, 0, 0}, 1, 0.7f);
  look({-1.0f, 1.5f, 0}, 2, 0.7f);
  look({0.45f, 0, 0.3f}, 4, 0.7f);
  look({1.35f, 0, 0.75f}, 5, 0.7f);
  const Eigen::Vector3f on(2.25f, 0, 1.2f);  // tread 8, facing up
  look(on, 3, 1.2f);
  const std::vector<storey::core::graph::FrontierCluster> below = floor_clusters(h);
  ASSERT_FALSE(below.empty());
  LocalPlanner lp(RobotModel{}, climbing_options(), 0.1);
  const auto view = h.map.view();
  Eigen::Vector3d foot = on.cast<double>();
  double yaw = 0, t = 0;
  int descents = 0, set_aside = 0;
  bool climbed = false;
  for (int cycle = 0; cycle < 12 && !climbed; ++cycle) {
    LocalPlanInput in = input(h, view, foot.cast<float>(), t);
    in.clusters = &below;
    in.robot_yaw_rad = yaw;
    in.last_resort = true;
    const LocalPlanResult r = lp.plan(in);
    set_aside = std::max(set_aside, r.clusters_set_aside);
    t += 0.5;
    if (r.status != LocalPlanStatus::kNewTrajectory) continue;
    const std::string reason = r.replan_reason;
    const auto end = r.trajectory.pose(r.trajectory.t_end());
    foot = end.foot_m, yaw = end.yaw_rad;
    t = r.trajectory.t_end() + 0.5;
    if (reason.rfind("descend", 0) == 0) {
      ++descents;
      foot = on.cast<double>(), yaw = 0;  // back up on the flight
    }
    climbed = reason.rfind("climb on", 0) == 0 && foot.z() > 1.6;
  }
  EXPECT_EQ(descents, 2);
  EXPECT_TRUE(climbed);
  EXPECT_EQ(set_aside, 0);
}

// On a flight the LiDAR, pitched up with the body, looks over the next treads: a tread ahead is
// often missing from the map and the one after it is two steps up. With flight_foot the climb on
// from mid-flight bridges such a gap as it does from the foot (house seed 6, session 16: a climb
// stopped on the flight by the look-ahead found nothing within a step ahead, and the robot stood
// there until "complete" with the upper floor at 1.5 %). Without: it stays.
TEST(LocalPlanner, WithFlightFootTheClimbOnBridgesATreadMissingFromTheMapOnTheFlight) {
  Harness h;
  const World w = flight_to_landing();
  // Seen from the floor (the risers) and from 2 m up (the treads' tops); the third tread (x
  // 0.6-0.9: the LiDAR's blind ring) and the landing (past x 2.1) not in the map.
  uint32_t seed = 1;
  for (const float up : {0.5f, 2.0f})
    for (const Eigen::Vector3f& f :
         {Eigen::Vector3f(-1.5f, 0.4f, 0), Eigen::Vector3f(-1.5f, -0.4f, 0)}) {
      std::vector<Eigen::Vector3f> pts;
      const Eigen::Vector3f s = f + Eigen::Vector3f(0, 0, up);
      for (const Eigen::Vector3f& p : storey::test::macro::scan(w, s, 100000, seed++))
        if (p.x() < 2.05f && !(p.x() > 0.58f && p.x() < 0.92f)) pts.push_back(p);
      h.insert(s, pts, f);
    }
  const auto view = h.map.view();
  const std::vector<storey::core::graph::FrontierCluster> none;
  auto plan_on_tread_2 = [&](bool flight_foot) {
    PlanOptions po;
    po.climb_blind = true;
    po.flight_foot = flight_foot;
    LocalPlanner lp(RobotModel{}, po, 0.1);
    LocalPlanInput in = input(h, view, {0.45f, 0, 0.3f}, 0.0);  // on the second tread, facing up
    in.clusters = &none;
    in.last_resort = true;
    return lp.plan(in);
  };
  const LocalPlanResult r = plan_on_tread_2(true);
  ASSERT_EQ(r.status, LocalPlanStatus::kNewTrajectory) << r.replan_reason;
  EXPECT_EQ(std::string(r.replan_reason).rfind("climb on", 0), 0u) << r.replan_reason;
  const auto end = r.trajectory.pose(r.trajectory.t_end());
  EXPECT_NEAR(end.foot_m.z(), 1.05, 0.06) << end.foot_m.transpose();  // up to the top tread
  EXPECT_NEAR(end.foot_m.y(), 0.0, 0.15) << end.foot_m.transpose();   // along the axis
  const LocalPlanResult off = plan_on_tread_2(false);
  EXPECT_NE(std::string(off.replan_reason).rfind("climb on", 0), 0u) << off.replan_reason;
}

// PlanOptions::brake_start: a robot moving when Stage 3 plans comes to rest |v|^2 / (2 a_max)
// further on before it follows the new trajectory (the control task's acceleration limit); the
// trajectory starts there where the way is clear (house seed 3, session 16: a new target behind
// the robot, the body turned while overshooting its start into a railing), else where it stands.
namespace {
// The start of the trajectory planned for a robot at `foot` moving at v in the corridor.
TrajectorySample planned_start(const PlanOptions& po, const Eigen::Vector3f& foot,
                               const Eigen::Vector2d& v) {
  Harness h;
  const World w = corridor();
  EXPECT_TRUE(scan_from(h, w, Eigen::Vector3f::Zero()));
  LocalPlanner lp(RobotModel{}, po, 0.1);
  const auto view = h.map.view();
  LocalPlanInput in = input(h, view, foot, 0.0);
  in.robot_velocity_mps = v;
  const LocalPlanResult r = lp.plan(in);
  EXPECT_EQ(r.status, LocalPlanStatus::kNewTrajectory) << r.replan_reason;
  if (r.status != LocalPlanStatus::kNewTrajectory) {
    TrajectorySample none;
    none.p_m.setConstant(NAN);
    return none;
  }
  return r.trajectory.sample(r.trajectory.t_start());
}
Eigen::Vector3d planned_start(bool brake, const Eigen::Vector3f& foot, const Eigen::Vector2d& v) {
  PlanOptions po;
  po.brake_start = brake;
  return planned_start(po, foot, v).p_m;
}
}  // namespace

TEST(LocalPlanner, AMovingRobotsTrajectoryStartsWhereItComesToRest) {
  const RobotModel robot;
  const Eigen::Vector2d v(0.8, 0.0);  // along the corridor: 0.32 m to rest at 1 m/s^2
  const double d = v.squaredNorm() / (2 * robot.max_accel_mps2);
  const Eigen::Vector3d on = planned_start(true, {0, 0, 0}, v);
  EXPECT_NEAR(on.x(), d, 0.03) << on.transpose();
  EXPECT_NEAR(on.y(), 0.0, 0.03) << on.transpose();
  const Eigen::Vector3d off = planned_start(false, {0, 0, 0}, v);
  EXPECT_NEAR(off.head<2>().norm(), 0.0, 0.03) << off.transpose();
  // Toward the wall 0.8 m away at 1 m/s (0.5 m to rest): the body, turning, would meet it on the
  // way; the start stays.
  const Eigen::Vector3d wall = planned_start(true, {0, 2.2f, 0}, {0.0, 1.0});
  EXPECT_NEAR(wall.y(), 2.2, 0.03) << wall.transpose();
  // Standing still: where it stands.
  const Eigen::Vector3d still = planned_start(true, {0, 0, 0}, {0.0, 0.0});
  EXPECT_NEAR(still.head<2>().norm(), 0.0, 0.03) << still.transpose();
}

// PlanOptions::brake_along_motion: the last published trajectory is one the control task may not
// have entered yet (it brakes on the one before, plan.brake_start). A robot moving against it
// comes to rest straight along its velocity, not along that trajectory behind it (house seed 5,
// session 32: a new start 0.17 m beside where the body came to rest, entered with a 125 deg
// turn).
TEST(LocalPlanner, ARobotMovingAgainstTheLastTrajectoryComesToRestAlongItsVelocity) {
  auto replanned_start = [](bool along_motion) {
    Harness h;
    const World w = corridor();
    EXPECT_TRUE(scan_from(h, w, Eigen::Vector3f::Zero()));
    PlanOptions po;
    po.brake_start = true;
    po.brake_along_motion = along_motion;
    LocalPlanner lp(RobotModel{}, po, 0.1);
    const auto view = h.map.view();
    LocalPlanInput in = input(h, view, {-2, 0, 0}, 0.0);
    const LocalPlanResult first = lp.plan(in);  // at rest, toward +x
    EXPECT_EQ(first.status, LocalPlanStatus::kNewTrajectory) << first.replan_reason;
    const TrajectorySample s0 = first.trajectory.sample(first.trajectory.t_start() + 1.0);
    EXPECT_GT(s0.v_mps.x(), 0.1);
    LocalPlanInput again = input(h, view, {-1.9f, 0, 0}, 0.5);
    again.robot_velocity_mps = {-0.8, 0.0};  // still moving the other way, on the one before
    lp.drop_target();  // a new target: a new trajectory from where braking ends
    const LocalPlanResult r = lp.plan(again);
    EXPECT_EQ(r.status, LocalPlanStatus::kNewTrajectory) << r.replan_reason;
    return r.trajectory.sample(r.trajectory.t_start()).p_m;
  };
  const Eigen::Vector3d along = replanned_start(true), old = replanned_start(false);
  EXPECT_NEAR(along.x(), -1.9 - 0.32, 0.03) << along.transpose();  // 0.8^2 / 2 behind it
  EXPECT_GT(old.x(), -1.9) << old.transpose();  // ahead along the trajectory: behind the motion
}

// PlanOptions::start_at_speed: the moving robot's new trajectory leaves its foot along its
// velocity at its speed (not at rest where braking would end); a robot slower than
// kAtSpeedMinMps, or heading into the wall 0.8 m away (the curve cannot keep 0.8 of the speed
// before it must turn), starts at rest as with brake_start alone.
TEST(LocalPlanner, AtSpeedAMovingRobotsTrajectoryLeavesWhereItIsAlongItsVelocity) {
  PlanOptions po;
  po.brake_start = true;
  po.start_at_speed = true;
  po.traj_retime = true;
  auto plan = [&](const Eigen::Vector3f& foot, const Eigen::Vector2d& v) {
    return planned_start(po, foot, v);
  };
  const Eigen::Vector2d v(0.8, 0.0);
  const TrajectorySample along = plan({-2, 0, 0}, v);  // 2 m before the viewpoint it plans to
  EXPECT_NEAR((along.p_m.head<2>() - Eigen::Vector2d(-2, 0)).norm(), 0.0, 0.03)
      << along.p_m.transpose();
  EXPECT_NEAR((along.v_mps.head<2>() - v).norm(), 0.0, 0.02) << along.v_mps.transpose();
  const TrajectorySample slow = plan({0, 0, 0}, {0.15, 0.0});
  EXPECT_NEAR(slow.v_mps.norm(), 0.0, 1e-9);
  const TrajectorySample wall = plan({0, 2.2f, 0}, {0.0, 1.0});
  EXPECT_NEAR(wall.v_mps.norm(), 0.0, 1e-9);
  EXPECT_NEAR(wall.p_m.y(), 2.2, 0.03) << wall.p_m.transpose();
}

// A climb found while other frontiers are left is deferred (the climb is one way): the robot
// first visits the others and comes back to the flight. PlanOptions::stale_floor_s: once the
// graph has not grown for that long, the climb is taken though frontiers remain (the teaching
// building's stair hub, session 19: clusters that came back whenever the map near them changed
// kept a climb deferred from 1020 s to the end, the upper floor unexplored). The harness's map
// is static, so the graph never grows here.
namespace {
struct DeferralRun {
  std::vector<std::string> reasons;  // of each new trajectory, in order
  bool climbed = false;              // a climb ending more than three treads up
  bool other_visited_first = false;  // the other cluster was the target before the climb
  bool flight_ignored = false;       // points over the flight, once the climb was deferred
  bool floor_ignored = false;        // points on the floor beside it, then
};

DeferralRun run_deferral(double stale_floor_s) {
  Harness h;
  observe_flight_room(h);
  PlanOptions po;
  po.climb_blind = true;
  po.flight_foot = true;
  po.stale_floor_s = stale_floor_s;
  const auto view = h.map.view();
  LocalPlanner lp(RobotModel{}, po, 0.1);
  // The clusters at the flight's foot, and one more on this floor (near the room's north-west).
  std::vector<storey::core::graph::FrontierCluster> clusters = clusters_at_foot(h);
  EXPECT_FALSE(clusters.empty());
  int32_t other = -1;
  for (const auto& c : h.clusters.clusters())
    if (c.centroid_m.x() < -1.5f && c.centroid_m.y() > 1.5f && c.centroid_m.z() < 0.1f) {
      clusters.push_back(c);
      other = c.id;
      break;
    }
  EXPECT_GE(other, 0);
  Eigen::Vector3f foot(-0.45f, 0.0f, 0);
  double yaw = 0, t = 0;
  DeferralRun run;
  for (int cycle = 0; cycle < 12 && !run.climbed; ++cycle) {
    const auto r = walked_cycle(lp, h, view, clusters, foot, yaw, t);
    if (!r) continue;
    run.reasons.push_back(r->replan_reason);
    if (r->target_cluster == other) run.other_visited_first = true;
    // Left for last: a frontier over the flight waits for the climb; one on the floor does not.
    if (run.reasons.back().rfind("climb left for last", 0) == 0) {
      run.flight_ignored = lp.ignored({1.5f, 0.1f, 0.75f}) && lp.ignored({3.3f, -0.2f, 1.65f});
      run.floor_ignored = lp.ignored({-1.0f, 1.5f, 0.0f}) || lp.ignored({1.5f, 1.5f, 0.0f});
    }
    if (run.reasons.back().rfind("climb on", 0) == 0 && foot.z() > 0.5f) run.climbed = true;
  }
  return run;
}

bool any_starts_with(const std::vector<std::string>& v, const std::string& prefix) {
  return std::any_of(v.begin(), v.end(),
                     [&](const std::string& s) { return s.rfind(prefix, 0) == 0; });
}
}  // namespace

// A trip back to a climb left for last is kept at periodic replans (until it collides, is
// overdue or arrives): replanned every replan_period_s, its route flipped between the two ways
// round a block of rooms and the robot never arrived (teaching_building seed 4, session 39).
TEST(LocalPlanner, ATripBackToAClimbLeftForLastIsNotReplannedPeriodically) {
  Harness h;
  observe_flight_room(h);
  LocalPlanner lp(RobotModel{}, climbing_options(), 0.1);
  const auto view = h.map.view();
  std::vector<storey::core::graph::FrontierCluster> clusters = clusters_at_foot(h);
  for (const auto& c : h.clusters.clusters())
    if (c.centroid_m.x() < -1.5f && c.centroid_m.y() > 1.5f && c.centroid_m.z() < 0.1f) {
      clusters.push_back(c);
      break;
    }
  Eigen::Vector3f foot(-0.45f, 0.0f, 0);
  double yaw = 0, t = 0;
  std::optional<LocalPlanResult> back;
  for (int cycle = 0; cycle < 12 && !back; ++cycle) {
    // Once the climb is left for last the robot sees to the floor's other frontiers: none left.
    const auto r = walked_cycle(lp, h, view, clusters, foot, yaw, t);
    if (r && std::string(r->replan_reason).rfind("climb left for last", 0) == 0) {
      clusters.clear();
      foot = Eigen::Vector3f(-3.3f, -2.3f, 0);  // the floor's last frontier, far from the flight
    }
    if (r && std::string(r->replan_reason).rfind("back to the flight left for last", 0) == 0)
      back = r;
  }
  ASSERT_TRUE(back.has_value());
  // walked_cycle put the robot at its end: back to where it was planned from, one period on.
  const BsplineTrajectory& tr = back->trajectory;
  const double t_on = std::min(tr.t_start() + LocalPlannerOptions{}.replan_period_s + 0.5,
                               0.5 * (tr.t_start() + tr.t_end()));
  const auto at = tr.pose(t_on);
  ASSERT_GT((at.foot_m - tr.pose(tr.t_end()).foot_m).head<2>().norm(), 0.6);
  const std::vector<storey::core::graph::FrontierCluster> none;
  LocalPlanInput in = input(h, view, at.foot_m.cast<float>(),
                            tr.t_start() + LocalPlannerOptions{}.replan_period_s + 0.5);
  in.clusters = &none;
  in.robot_yaw_rad = at.yaw_rad;
  in.last_resort = true;
  const LocalPlanResult r = lp.plan(in);
  EXPECT_EQ(r.status, LocalPlanStatus::kKeep) << to_string(r.status) << " " << r.replan_reason;
}

TEST(LocalPlanner, AClimbLeftForLastIsTakenOnceTheFloorsGraphStopsGrowing) {
  const DeferralRun wait = run_deferral(0.0);  // off: the climb waits for the other cluster
  EXPECT_TRUE(any_starts_with(wait.reasons, "climb left for last"));
  EXPECT_TRUE(wait.other_visited_first);
  EXPECT_TRUE(wait.climbed);
  EXPECT_TRUE(any_starts_with(wait.reasons, "climb on: the floor is done"));

  const DeferralRun stale = run_deferral(5.0);  // the graph has not grown for 5 s
  EXPECT_TRUE(stale.climbed);
  EXPECT_FALSE(stale.other_visited_first);
  EXPECT_TRUE(any_starts_with(stale.reasons, "climb on: the floor's graph stopped growing"));

  const DeferralRun late = run_deferral(600.0);  // not stale within the run: as with it off
  EXPECT_EQ(late.reasons, wait.reasons);
}

// Meanwhile a frontier over that flight is no target: the climb sees it (house seed 4, session
// 22: a climb deferred at the foot, the robot sent up the flight to its frontiers, back down and
// up again five times in 120 s). One on the floor beside it still is.
TEST(LocalPlanner, AFrontierOverTheFlightLeftForLastIsNoTargetMeanwhile) {
  const DeferralRun run = run_deferral(0.0);
  ASSERT_TRUE(any_starts_with(run.reasons, "climb left for last"));
  EXPECT_TRUE(run.flight_ignored);
  EXPECT_FALSE(run.floor_ignored);
}

// GraphNode::flight_lead: the first flight of a U-shaped stair (walled, a landing with a wall
// ahead) seen from the floor is in the map but out of C_reach, and no frontier is left on the
// floor. With flight_foot the robot goes to the flight's foot and climbs; without it the floor
// ends "no frontiers" (teaching_building seed 1, session 23: the flight's foot frontier was
// cleared from the side, the run ended "complete" with the upper floor unexplored).
namespace {
World walled_flight_room() {
  World w;
  w.add({-4, -3, -0.2f}, {6, 3, 0});
  w.stairs(0.0f, -0.6f, 0.6f, 0.0f, 7, 0.17f, 0.29f);  // up to 1.19 m at x = 2.03
  w.add({2.03f, -0.6f, -0.2f}, {3.4f, 0.6f, 1.19f});   // the landing
  w.add({3.4f, -0.72f, 0}, {3.6f, 0.72f, 3.5f});       // its wall
  w.add({0, -0.72f, 0}, {3.4f, -0.6f, 3.5f});          // the stairwell's sides
  w.add({0, 0.6f, 0}, {3.4f, 0.72f, 3.5f});
  w.add({-4, -3.2f, 0}, {6, -3, 3.5f});  // the room's walls
  w.add({-4, 3, 0}, {6, 3.2f, 3.5f});
  w.add({-4.2f, -3, 0}, {-4, 3, 3.5f});
  return w;
}

// walled_flight_room() seen from three places on the floor, with flight leads.
void observe_walled_flight_room(Harness& h) {
  const World w = walled_flight_room();
  for (const Eigen::Vector3f& f :
       {Eigen::Vector3f(-2.5f, 0.1f, 0), Eigen::Vector3f(-1.5f, -1.2f, 0),
        Eigen::Vector3f(-0.8f, 1.0f, 0)})
    h.observe(w, f, 60000, 3);
}

// Graph options with flight leads (climb_frontiers).
storey::core::graph::GraphOptions lead_options() {
  storey::core::graph::GraphOptions go;
  go.climb_frontiers = true;
  return go;
}

// The defaults' climbing switches: blind climbs from a flight's foot.
}  // namespace

TEST(LocalPlanner, WithNoFrontierLeftTheRobotClimbsAFlightThatRisesOutOfReach) {
  storey::core::graph::GraphOptions go;
  go.climb_frontiers = true;
  Harness h(go);
  observe_walled_flight_room(h);
  int leads = 0;
  for (storey::core::graph::NodeId i = 0; i < h.graph.node_capacity(); ++i)
    leads += h.graph.node(i).alive && h.graph.node(i).flight_lead;
  ASSERT_GT(leads, 0);
  const std::vector<storey::core::graph::FrontierCluster> none;
  for (const bool on : {true, false}) {
    SCOPED_TRACE(on ? "flight_foot on" : "off");
    PlanOptions po;
    po.climb_blind = true;
    po.flight_foot = on;
    const auto view = h.map.view();
    LocalPlanner lp(RobotModel{}, po, 0.1);
    Eigen::Vector3f foot(-2.5f, 0.1f, 0);
    double yaw = 0, t = 0;
    bool to_foot = false, climbed = false;
    for (int cycle = 0; cycle < 6 && !climbed; ++cycle) {
      const auto r = walked_cycle(lp, h, view, none, foot, yaw, t);
      if (!r) continue;
      const std::string reason = r->replan_reason;
      to_foot |= reason.rfind("to a flight's foot: the floor is done", 0) == 0;
      climbed = reason.rfind("climb on", 0) == 0 && foot.z() > 0.5f;
    }
    EXPECT_EQ(to_foot, on);
    EXPECT_EQ(climbed, on);
    if (!on) {
      LocalPlanInput in = input(h, view, foot, t);
      in.clusters = &none;
      in.last_resort = true;
      EXPECT_EQ(lp.plan(in).status, LocalPlanStatus::kNoFrontiers);
    }
  }
}

// A trip to a lead's flight cut short (here overdue, the robot never moved; teaching_building
// seed 1, session 23: frontiers came back on the way and the foot, tried once, was never tried
// again) is taken up again once the floor has no target, a bounded number of times.
TEST(LocalPlanner, ATripToAFlightLeadCutShortIsTakenUpAgain) {
  Harness h(lead_options());
  observe_walled_flight_room(h);
  PlanOptions po = climbing_options();
  const auto view = h.map.view();
  LocalPlanner lp(RobotModel{}, po, 0.1);
  const std::vector<storey::core::graph::FrontierCluster> none;
  const Eigen::Vector3f foot(-2.5f, 0.1f, 0);
  double t = 0;
  int trips = 0, found = 0;
  for (int cycle = 0; cycle < 10; ++cycle) {
    LocalPlanInput in = input(h, view, foot, t);
    in.clusters = &none;
    in.last_resort = true;
    const LocalPlanResult r = lp.plan(in);
    if (r.status == LocalPlanStatus::kNewTrajectory) {
      const std::string reason = r.replan_reason;
      EXPECT_EQ(reason.rfind("to a flight's foot", 0), 0u) << reason;
      // Then the same flight as one found that never led up (to_found_flight).
      (reason.find("never led up") != std::string::npos ? found : trips)++;
      t = r.trajectory.t_end() + 4.0;  // overdue: the robot did not move
    } else {
      t += 1.0;
    }
  }
  EXPECT_EQ(trips, 3);  // the first trip and two more (kMaxLeadTrips)
  EXPECT_EQ(found, 2);  // kMaxFoundFlightTrips
}

// A flight found on this floor that never led up (here its foot was walked to, the trip ended
// overdue, the robot never climbed) is gone to again once no target is left, before the
// verdict: teaching_building seed 4 (session 39) descended its first flight twice early on and
// ended "complete" at 1034 s with the floor above never explored. Without it: kNoFrontiers.
TEST(LocalPlanner, AFlightFoundThatNeverLedUpIsGoneToBeforeNoTargetIsTheVerdict) {
  Harness h;
  observe_flight_room(h);
  FootTrip trip(h);
  const std::optional<LocalPlanResult> first = trip.to_foot();
  ASSERT_TRUE(first);
  // Much later, the robot elsewhere on the floor (it never reached the foot), no frontier left.
  const Eigen::Vector3f far(-3.0f, -2.0f, 0);
  double t = first->trajectory.t_end() + 30.0;
  std::optional<LocalPlanResult> back;
  for (int cycle = 0; cycle < 4 && !back; ++cycle, t += 1.0) {
    LocalPlanResult r = trip.without_frontiers(far, 0.0, t);
    if (r.status == LocalPlanStatus::kNewTrajectory) back = std::move(r);
  }
  ASSERT_TRUE(back.has_value());
  EXPECT_NE(std::string(back->replan_reason).find("never led up"), std::string::npos)
      << back->replan_reason;
  EXPECT_LT((back->target_m - first->target_m).head<2>().norm(), 0.8)
      << back->target_m.transpose() << " vs " << first->target_m.transpose();
}

// PlanOptions::stale_floor_s: once the floor's graph has stopped growing, a lead's flight is gone
// to though other frontiers remain (teaching_building seed 1, session 23: frontiers kept coming
// back near the stair hub, no cycle without a target came before 1800 s and the lead trip waited
// for one). The harness's map is static: the graph never grows. The robot stays where it is
// while it heads for the other frontier (periodic replans) and walks to a flight's foot.
namespace {
struct LeadRun {
  std::vector<std::string> reasons;  // of each new trajectory, in order
  bool climbed = false;              // a climb ending more than three treads up
};

LeadRun run_lead(double stale_floor_s) {
  Harness h(lead_options());
  observe_walled_flight_room(h);
  PlanOptions po = climbing_options();
  po.stale_floor_s = stale_floor_s;
  const auto view = h.map.view();
  LocalPlanner lp(RobotModel{}, po, 0.1);
  // One frontier cluster on the floor, the farthest from the flight's foot.
  std::vector<storey::core::graph::FrontierCluster> clusters;
  for (const auto& c : h.clusters.clusters())
    if (c.centroid_m.z() < 0.1f &&
        (clusters.empty() ||
         c.centroid_m.head<2>().norm() > clusters[0].centroid_m.head<2>().norm()))
      clusters = {c};
  EXPECT_EQ(clusters.size(), 1u);
  Eigen::Vector3f foot(-2.5f, 0.1f, 0);
  double yaw = 0, t = 0;
  LeadRun run;
  for (int cycle = 0; cycle < 16 && !run.climbed; ++cycle) {
    LocalPlanInput in = input(h, view, foot, t);
    in.clusters = &clusters;
    in.robot_yaw_rad = yaw;
    in.last_resort = true;
    const LocalPlanResult r = lp.plan(in);
    t += 1.0;
    if (r.status != LocalPlanStatus::kNewTrajectory) continue;
    const std::string reason = r.replan_reason;
    run.reasons.push_back(reason);
    if (reason.rfind("to a flight's foot", 0) != 0 && reason.rfind("climb on", 0) != 0) continue;
    const auto end = r.trajectory.pose(r.trajectory.t_end());  // walked to its end
    foot = end.foot_m.cast<float>();
    yaw = end.yaw_rad;
    t = r.trajectory.t_end() + 1.5;
    if (reason.rfind("climb on", 0) == 0 && foot.z() > 0.5f) run.climbed = true;
  }
  return run;
}
}  // namespace

TEST(LocalPlanner, AFlightLeadIsGoneToOnceTheFloorsGraphStopsGrowing) {
  const LeadRun wait = run_lead(0.0);  // off: the lead waits until the floor has no target
  EXPECT_FALSE(any_starts_with(wait.reasons, "to a flight's foot"));
  EXPECT_FALSE(wait.climbed);

  const LeadRun stale = run_lead(5.0);  // the graph has not grown for 5 s
  EXPECT_TRUE(any_starts_with(stale.reasons, "to a flight's foot: the floor's graph stopped"));
  EXPECT_TRUE(stale.climbed);

  const LeadRun late = run_lead(600.0);  // not stale within the run: as with it off
  EXPECT_EQ(late.reasons, wait.reasons);
}

// The walk to a flight's foot follows G_real where the voxel A* gives up (here bounded to one
// expansion; on a real floor, a trip across the building past its expansion limit): the foot is
// no graph node, so the walk goes to the nearest linked one and on to the foot.
TEST(LocalPlanner, AFlightsFootIsWalkedToAlongTheGraphWhereTheVoxelSearchGivesUp) {
  Harness h(lead_options());
  observe_walled_flight_room(h);
  PlanOptions po = climbing_options();
  po.astar_max_expansions = 1;
  const auto view = h.map.view();
  LocalPlanner lp(RobotModel{}, po, 0.1);
  const std::vector<storey::core::graph::FrontierCluster> none;
  Eigen::Vector3f foot(-2.5f, 0.1f, 0);
  double yaw = 0, t = 0;
  const auto r = walked_cycle(lp, h, view, none, foot, yaw, t);
  ASSERT_TRUE(r.has_value());
  EXPECT_EQ(std::string(r->replan_reason).rfind("to a flight's foot", 0), 0u) << r->replan_reason;
  EXPECT_GT(r->graph_fallbacks, 0);
  // It ends at the foot's stand point (on the flight's axis, short of its first riser at x = 0).
  EXPECT_LT(std::abs(foot.y()), 0.3f) << foot.transpose();
  EXPECT_GT(foot.x(), -1.5f) << foot.transpose();
  EXPECT_LT(foot.x(), 0.0f) << foot.transpose();
}

// A U-shaped return stair (as in the teaching building): flight 1 along +x to a landing walled
// ahead, flight 2 back along -x beside it. The climb of flight 1 ends on the landing; from there
// the robot is sent to flight 2's foot, facing up it, whatever else is left below
// (teaching_building seed 1, session 24: from the landing the robot was sent back down flight 1
// to the ground floor's frontiers, reachable again through it, and flight 2 was never climbed).
// The climb from that foot is measured in the simulator (docs/RESULTS.md "Session 24"): on this
// harness's static map Stage 3's path centring ends the walk 0.25 m off the axis and the climb
// from there finds no flight.
namespace {
World u_stair_room() {
  World w;
  const float rise = 0.168f, run = 0.29f;
  w.add({-4, -3, -0.2f}, {6, 4, 0});
  w.stairs(0.0f, -0.6f, 0.6f, 0.0f, 8, rise, run);
  w.add({2.32f, -0.6f, -0.2f}, {3.72f, 2.0f, 9 * rise});  // the landing
  for (int k = 0; k < 9; ++k)  // flight 2, back along -x from the landing's edge
    w.add({2.32f - (k + 1) * run, 0.8f, -0.2f}, {2.32f - k * run, 2.0f, (10 + k) * rise});
  w.add({-0.29f, -0.72f, 0}, {3.84f, -0.6f, 4.2f});  // outer walls
  w.add({-0.29f, 2.0f, 0}, {3.84f, 2.12f, 4.2f});
  w.add({-0.29f, 0.6f, 0}, {2.32f, 0.8f, 4.2f});    // between the flights
  w.add({3.72f, -0.72f, 0}, {3.84f, 2.12f, 4.2f});  // the landing's end wall
  w.add({-4, -3.2f, 0}, {6, -3, 4.5f});             // the room's walls
  w.add({-4, 4, 0}, {6, 4.2f, 4.5f});
  w.add({-4.2f, -3, 0}, {-4, 4, 4.5f});
  return w;
}

// u_stair_room() seen from the floor; the frontier on flight 1's lower treads is the target and
// the robot climbs from its foot, walking each trajectory to its end (foot, yaw, t).
struct UStairClimb {
  const World w = u_stair_room();
  Harness h{lead_options()};
  LocalPlanner lp{RobotModel{}, climbing_options(), 0.1};
  std::vector<storey::core::graph::FrontierCluster> on_flight;
  Eigen::Vector3f foot{-2.5f, 0.1f, 0};
  double yaw = 0, t = 0;

  UStairClimb() {
    for (const Eigen::Vector3f& f :
         {Eigen::Vector3f(-2.5f, 0.1f, 0), Eigen::Vector3f(-1.5f, -1.2f, 0),
          Eigen::Vector3f(-1.5f, 2.5f, 0)})
      h.observe(w, f, 60000, 3);
    for (const auto& c : h.clusters.clusters())
      if (c.centroid_m.z() > 0.1f) on_flight.push_back(c);
  }
  // Plans until the robot stands on the landing (true; its foot at the landing's height).
  bool to_landing() {
    for (int cycle = 0; cycle < 8; ++cycle) {
      const auto view = h.map.view();
      if (walked_cycle(lp, h, view, on_flight, foot, yaw, t) &&
          std::abs(foot.z() - 1.512f) < 0.1f && foot.x() > 2.4f) {
        foot.z() = 9 * 0.168f;
        return true;
      }
    }
    return false;
  }
};
}  // namespace

TEST(LocalPlanner, FromTheLandingOfAUShapedStairTheRobotGoesToItsReturnFlight) {
  UStairClimb u;
  ASSERT_FALSE(u.on_flight.empty());
  ASSERT_TRUE(u.to_landing());
  // The robot stands on the landing and looks round.
  u.h.observe(u.w, u.foot, 60000, 5);
  u.h.observe(u.w, u.foot + Eigen::Vector3f(0.2f, 0.6f, 0), 60000, 6);
  std::optional<LocalPlanResult> next;  // the first plan once the climb has ended there
  for (int cycle = 0; cycle < 4 && !next; ++cycle) {
    const auto view = u.h.map.view();
    next = walked_cycle(u.lp, u.h, view, u.on_flight, u.foot, u.yaw, u.t);
  }
  ASSERT_TRUE(next.has_value());
  EXPECT_EQ(std::string(next->replan_reason).rfind("to a flight's foot: from the landing", 0), 0u)
      << next->replan_reason;
  // Flight 2's foot: on the landing before its first riser (x 2.32), in its lane (y 0.8..2.0),
  // facing back along -x.
  EXPECT_GT(next->target_m.x(), 2.32 + 0.3) << next->target_m.transpose();
  EXPECT_GT(next->target_m.y(), 1.0) << next->target_m.transpose();
  EXPECT_LT(next->target_m.y(), 1.8) << next->target_m.transpose();
  EXPECT_NEAR(next->target_m.z(), 1.512, 0.05);
  EXPECT_NEAR(std::abs(next->target_yaw_rad), M_PI, 0.2);
}

// The same climb, but the landing under the robot, reached blind, is not in the map yet (its
// first scan has no return within 0.8 m of the sensor: the LiDAR's blind ring): flight 2's foot
// is seen, but the voxel search finds no path from where the robot stands. The robot walks
// straight across the landing to flight 2's foot (else it would wait there, kSettling, while the
// landing's map fills in). Without either it had not gone there 6 s later; in teaching_building
// seed 3 (session 39) the floor below drew it back down the flight just climbed.
TEST(LocalPlanner, OnALandingNotInTheMapYetTheRobotStillGoesToTheReturnFlight) {
  UStairClimb u;
  ASSERT_FALSE(u.on_flight.empty());
  ASSERT_TRUE(u.to_landing());
  Harness& h = u.h;
  const World& w = u.w;
  LocalPlanner& lp = u.lp;
  const Eigen::Vector3f foot = u.foot;
  double yaw = u.yaw, t = u.t;
  const Eigen::Vector3f sensor = foot + Eigen::Vector3f(0, 0, 0.5f);
  std::vector<Eigen::Vector3f> pts;
  for (const Eigen::Vector3f& p : storey::test::macro::scan(w, sensor, 60000, 5))
    if ((p - sensor).head<2>().norm() > 0.8f) pts.push_back(p);
  h.insert(sensor, pts, foot);
  // The clusters as the map task would give them now: the flight's, and any on the landing.
  std::vector<storey::core::graph::FrontierCluster> left;
  for (const auto& c : h.clusters.clusters()) left.push_back(c);
  int waits = 0;
  std::optional<LocalPlanResult> next;
  for (int cycle = 0; cycle < 6 && !next; ++cycle) {
    const auto view = h.map.view();
    LocalPlanInput in = input(h, view, foot, t);
    in.clusters = &left;
    in.robot_yaw_rad = yaw;
    in.last_resort = true;
    LocalPlanResult r = lp.plan(in);
    t += 1.0;
    if (r.status == LocalPlanStatus::kNewTrajectory) {
      next = std::move(r);
    } else {
      ASSERT_EQ(r.status, LocalPlanStatus::kSettling) << to_string(r.status);
      ++waits;
      if (waits == 2) h.observe(w, foot, 60000, 6);  // the landing's map fills in
    }
  }
  EXPECT_LE(waits, 2);
  ASSERT_TRUE(next.has_value());
  EXPECT_EQ(std::string(next->replan_reason).rfind("to a flight's foot: from the landing", 0), 0u)
      << next->replan_reason;
  EXPECT_NEAR(std::abs(next->target_yaw_rad), M_PI, 0.2);            // facing up flight 2
  EXPECT_GT(next->target_m.y(), 1.0) << next->target_m.transpose();  // flight 2's lane
  EXPECT_NEAR(next->target_m.z(), 1.512, 0.05);
}

// PlanOptions::reach_off_graph. A 2 m corridor whose graph grew over its length, then narrowed
// to a 0.8 m opening at x = 5: the graph is cut there (GraphOptions::keep_reachable_cut keeps the
// far part, expansion slowed to one node per update does not re-link it), so the frontier at the
// far end has no path along G_real from the robot (the office, seed 1, session 26: a room whose
// graph had no edge through its door). The map still has a way through the opening for the
// 0.41 m wide body. Off: no reachable target. On: Stage 3 on the map takes the robot through.
namespace {
World long_corridor() {
  World w;
  w.add({-3, -1, -0.2f}, {30, 1, 0});
  w.add({-3, -1.2f, 0}, {30, -1, 2.5f});
  w.add({-3, 1, 0}, {30, 1.2f, 2.5f});
  w.add({-3.2f, -1.2f, 0}, {-3, 1.2f, 2.5f});
  return w;
}

storey::core::graph::GraphOptions cut_graph_options() {
  storey::core::graph::GraphOptions go;
  go.keep_reachable_cut = true;
  go.max_expansions_per_update = 1;
  return go;
}

// The corridor observed over its length, then narrowed to the opening and observed from the
// robot's foot (returned), short of it.
Eigen::Vector3f observe_cut_corridor(Harness& h) {
  World w = long_corridor();
  for (float x : {0.f, 3.f, 7.f, 10.f})
    h.observe(w, Eigen::Vector3f(x, 0, 0), 100000, 11 + uint32_t(x));
  w.add({5.0f, -1.0f, 0.0f}, {5.2f, -0.4f, 2.5f});
  w.add({5.0f, 0.4f, 0.0f}, {5.2f, 1.0f, 2.5f});
  const Eigen::Vector3f foot(3.5f, 0, 0);
  for (uint32_t r = 0; r < 3; ++r) h.observe(w, foot, 100000, 40 + r);
  return foot;
}

struct OffGraphRun {
  LocalPlanStatus status = LocalPlanStatus::kBadInput;
  std::string reason;
  int unreachable = 0;
  double end_x_m = 0;  // the trajectory's end
  double max_x_m = 0;  // the farthest frontier node
};

OffGraphRun run_off_graph(bool on) {
  Harness h(cut_graph_options(), 3);
  const Eigen::Vector3f foot = observe_cut_corridor(h);
  PlanOptions po;
  po.reach_off_graph = on;
  LocalPlanner lp(RobotModel{}, po, 0.1);
  const auto view = h.map.view();
  std::vector<storey::core::graph::FrontierCluster> far;  // beyond the cut
  for (const auto& c : h.clusters.clusters())
    if (c.centroid_m.x() > 5.3f) far.push_back(c);
  LocalPlanInput in = input(h, view, foot, 0.0);
  in.clusters = &far;
  in.last_resort = true;
  const LocalPlanResult r = lp.plan(in);
  OffGraphRun run;
  run.status = r.status;
  run.reason = r.replan_reason;
  run.unreachable = r.clusters_unreachable;
  if (r.status == LocalPlanStatus::kNewTrajectory)
    run.end_x_m = r.trajectory.pose(r.trajectory.t_end()).foot_m.x();
  for (const auto& c : far)
    for (auto n : c.nodes) run.max_x_m = std::max(run.max_x_m, double(h.graph.node(n).p_m.x()));
  return run;
}
}  // namespace

TEST(LocalPlanner, FrontiersWithNoPathAlongTheGraphAreReachedOnTheMapWithReachOffGraph) {
  const OffGraphRun off = run_off_graph(false);
  ASSERT_GT(off.max_x_m, 12.0);  // the far end's frontier, beyond the cut
  ASSERT_GT(off.unreachable, 0);
  EXPECT_EQ(off.status, LocalPlanStatus::kNoReachableTarget);
  const OffGraphRun on = run_off_graph(true);
  EXPECT_EQ(on.unreachable, off.unreachable);
  ASSERT_EQ(on.status, LocalPlanStatus::kNewTrajectory);
  EXPECT_EQ(on.reason.rfind("off the graph", 0), 0u) << on.reason;
  EXPECT_GT(on.end_x_m, 5.5);  // through the opening
}

// to_off_graph's attempts are bounded per cycle; the next cycle takes up the viewpoints after
// those tried, and the search is not over (kSearching) until every one has been. Before, each
// cycle tried the same first viewpoints of the first cluster, it was never set aside nor the
// others tried, and the run ended "complete" with the office's upper floor at 87.3 % (seed 3).
// Here the body is wider than the opening: no viewpoint beyond it is reached, 2 attempts a cycle.
TEST(LocalPlanner, OffGraphViewpointsAreAllTriedOverCyclesBeforeTheSearchEnds) {
  Harness h(cut_graph_options(), 3);
  const Eigen::Vector3f foot = observe_cut_corridor(h);
  PlanOptions po;
  po.reach_off_graph = true;
  po.path_retries = false;
  LocalPlannerOptions lo;
  lo.max_stage3_attempts = 2;
  RobotModel wide;
  wide.body_width_m = 0.9;
  LocalPlanner lp(wide, po, 0.1, lo);
  const auto view = h.map.view();
  std::vector<storey::core::graph::FrontierCluster> far;  // beyond the opening
  for (const auto& c : h.clusters.clusters())
    if (c.centroid_m.x() > 5.3f) far.push_back(c);
  ASSERT_FALSE(far.empty());
  LocalPlanInput in = input(h, view, foot, 0.0);
  in.clusters = &far;
  in.last_resort = true;
  int searching = 0;
  LocalPlanResult r;
  for (int cycle = 0; cycle < 40; ++cycle) {
    in.t_s = 0.5 * cycle;
    r = lp.plan(in);
    ASSERT_NE(r.status, LocalPlanStatus::kNewTrajectory) << r.replan_reason;
    if (r.status != LocalPlanStatus::kSearching) break;
    ++searching;
  }
  EXPECT_GT(searching, 0);
  EXPECT_EQ(r.status, LocalPlanStatus::kNoReachableTarget);
  // Every cluster beyond the opening was tried from each of its viewpoints and set aside (the
  // counts are the cycle's start: one cycle more).
  in.t_s += 0.5;
  r = lp.plan(in);
  EXPECT_EQ(r.status, LocalPlanStatus::kNoReachableTarget);
  EXPECT_EQ(r.clusters_set_aside, int(far.size()));
  EXPECT_EQ(r.clusters_unreachable, 0);
}

// The off-graph clusters are tried on the robot's level first (office seed 5, session 33: a
// cluster on the floor below, nearest in 3D, spent every cycle's Stage 3 attempts), nearest
// first within each level.
TEST(LocalPlanner, OffGraphClustersOnTheRobotsLevelAreTriedFirst) {
  const Eigen::Vector3f robot(13.2f, 12.2f, 3.0f);
  const std::vector<Eigen::Vector3f> reps = {
      {17.3f, 7.4f, 0.0f},   // the floor below, 7.2 m away
      {4.9f, 8.1f, 3.0f},    // the robot's floor, 9.3 m away
      {21.4f, 13.9f, 2.8f},  // the flight's top, within the band
      {12.0f, 11.0f, 0.2f},  // below, 3.1 m away
      {9.0f, 12.0f, 3.3f}};  // the robot's floor, 4.2 m away
  const std::vector<size_t> order = off_graph_order(reps, robot, 0.6f);
  EXPECT_EQ(order, (std::vector<size_t>{4, 2, 1, 3, 0}));
  EXPECT_EQ(off_graph_order({}, robot, 0.6f).size(), 0u);
}

namespace {
// The corridor with the gate, scanned from the origin: the easternmost cluster (the graph stops
// at the gate) and a viewpoint of it at `at` (on the graph node nearest it) facing `yaw`.
struct GateScene {
  Harness h;
  std::vector<storey::core::graph::FrontierCluster> east;
  GateScene() {
    World w = long_corridor();
    w.add({2.7f, -1.0f, 0.0f}, {3.3f, -0.35f, 2.5f});
    w.add({2.7f, 0.35f, 0.0f}, {3.3f, 1.0f, 2.5f});
    h.observe(w, Eigen::Vector3f(0, 0, 0), 100000, 5);
    for (const auto& c : h.clusters.clusters())
      if (east.empty() || c.centroid_m.x() > east[0].centroid_m.x()) east.assign(1, c);
    EXPECT_FALSE(east.empty());
  }
  std::vector<storey::core::graph::ClusterViewpoints> viewpoint(const Eigen::Vector3f& at,
                                                                double yaw) const {
    const auto node = h.graph.nearest(at, 1.5f, 0.5f);
    EXPECT_NE(node, storey::core::graph::kNoId);
    if (east.empty() || node == storey::core::graph::kNoId) return {};
    storey::core::graph::ClusterViewpoints cv;
    cv.cluster_id = east[0].id;
    storey::core::graph::Viewpoint v;
    v.node = node;
    v.p_m = at;
    v.yaw_rad = float(yaw);
    v.visible = 1;
    cv.viewpoints.push_back(v);
    return {cv};
  }
};

// PlanOptions::arrive_along_path. A 2 m corridor with a gate 0.7 m wide and 0.6 m long 3 m
// ahead: the 0.8 m body box (0.7 m and its margins) walks through it but cannot stand across it.
// A viewpoint in the gate facing across the corridor (as one beside a ramp's edge faced a
// frontier behind the robot on test_ramp, session 26): off, every trajectory to it collides where
// it turns and the cluster fails Stage 3; on, the robot arrives there facing along the corridor.
struct ArriveRun {
  LocalPlanStatus status = LocalPlanStatus::kBadInput;
  Eigen::Vector3d end_m = Eigen::Vector3d::Zero();
  double end_yaw_rad = 0;
  double duration_s = 0;
};

// The cluster's one viewpoint at `at` facing `yaw` (default: in the gate, facing across).
ArriveRun run_arrive(const PlanOptions& po, const Eigen::Vector3f& at = Eigen::Vector3f(3, 0, 0),
                     double yaw = M_PI / 2) {
  const GateScene s;
  const auto vps = s.viewpoint(at, yaw);
  ArriveRun run;
  if (vps.empty()) return run;
  LocalPlanner lp(RobotModel{}, po, 0.1);
  const auto view = s.h.map.view();
  LocalPlanInput in = input(s.h, view, Eigen::Vector3f(0, 0, 0), 0.0);
  std::vector<storey::core::graph::FrontierCluster> east = s.east;
  in.clusters = &east;
  in.viewpoints = &vps;
  const LocalPlanResult r = lp.plan(in);
  run.status = r.status;
  if (r.status == LocalPlanStatus::kNewTrajectory) {
    const auto end = r.trajectory.pose(r.trajectory.t_end());
    run.end_m = end.foot_m;
    run.end_yaw_rad = end.yaw_rad;
    run.duration_s = r.trajectory.duration();
  }
  return run;
}

PlanOptions arrive_along_path(bool on) {
  PlanOptions po;
  po.arrive_along_path = on;
  return po;
}

// PlanOptions::keep_on_failed_replan. The robot walks toward a viewpoint 2.2 m down the
// corridor; at the periodic replan (it has not moved: held up) the cluster's only viewpoint is
// one in the gate facing across, which no trajectory reaches (as a replan from a corner of the
// maze found no room to turn, session 26). The trajectory followed is still free: on, it stays;
// off, the replan ends in something else (no reachable target; with a `twin` cluster behind the
// robot, a turn back to it).
LocalPlanResult failed_replan(bool on, bool twin) {
  const GateScene s;
  auto vps = s.viewpoint(Eigen::Vector3f(2.2f, 0, 0), 0.0);
  auto across = s.viewpoint(Eigen::Vector3f(3, 0, 0), M_PI / 2);
  auto back = s.viewpoint(Eigen::Vector3f(-1.5f, 0, 0), M_PI);
  if (vps.empty() || across.empty() || back.empty()) return {};
  PlanOptions po;
  po.keep_on_failed_replan = on;
  po.target_momentum = true;  // the target's cluster stays first in the tour
  LocalPlanner lp(RobotModel{}, po, 0.1);
  const auto view = s.h.map.view();
  LocalPlanInput in = input(s.h, view, Eigen::Vector3f(0, 0, 0), 0.0);
  std::vector<storey::core::graph::FrontierCluster> clusters = s.east;
  in.clusters = &clusters;
  in.viewpoints = &vps;
  const LocalPlanResult r0 = lp.plan(in);
  EXPECT_EQ(r0.status, LocalPlanStatus::kNewTrajectory) << r0.replan_reason;
  in.t_s = LocalPlannerOptions{}.replan_period_s + 0.5;
  if (twin) {  // the same frontier nodes under another id, seen from behind the robot
    clusters.push_back(s.east[0]);
    clusters.back().id = s.east[0].id + 1;
    back[0].cluster_id = clusters.back().id;
    across.push_back(back[0]);
  }
  in.viewpoints = &across;
  return lp.plan(in);
}
}  // namespace

TEST(LocalPlanner,
     APeriodicReplanThatFindsNoTrajectoryToItsTargetKeepsTheOneFollowedWithKeepOnFailedReplan) {
  const LocalPlanResult off = failed_replan(false, false);
  EXPECT_EQ(off.status, LocalPlanStatus::kNoReachableTarget) << off.replan_reason;
  const LocalPlanResult on = failed_replan(true, false);
  ASSERT_EQ(on.status, LocalPlanStatus::kKeep) << on.replan_reason;
  EXPECT_STREQ(on.replan_reason,
               "periodic replan found no trajectory: the one followed is still free");
  EXPECT_NEAR(on.target_m.x(), 2.2, 0.3);
  EXPECT_GT(on.real_until_s, 1.0);
  // The target's cluster failed, the twin behind the robot did not: off, the robot turns back.
  const LocalPlanResult off_twin = failed_replan(false, true);
  ASSERT_EQ(off_twin.status, LocalPlanStatus::kNewTrajectory) << off_twin.replan_reason;
  EXPECT_LT(off_twin.target_m.x(), 0.0);
  const LocalPlanResult on_twin = failed_replan(true, true);
  ASSERT_EQ(on_twin.status, LocalPlanStatus::kKeep) << on_twin.replan_reason;
  EXPECT_NEAR(on_twin.target_m.x(), 2.2, 0.3);
}

TEST(LocalPlanner, AViewpointTheBodyCannotTurnToIsReachedFacingAlongThePathWithArriveAlongPath) {
  const ArriveRun off = run_arrive(arrive_along_path(false));
  EXPECT_EQ(off.status, LocalPlanStatus::kNoReachableTarget);
  const ArriveRun on = run_arrive(arrive_along_path(true));
  ASSERT_EQ(on.status, LocalPlanStatus::kNewTrajectory);
  EXPECT_LT((on.end_m - Eigen::Vector3d(3, 0, 0)).head<2>().norm(), 0.3);
  EXPECT_LT(std::abs(std::remainder(on.end_yaw_rad, 2 * M_PI)), 0.35);  // along the corridor
}

// PlanOptions::face_cluster. A viewpoint 2 m down the corridor facing back at the robot (its
// cluster behind it, as Sec. III-C's yaw faces a centroid the robot has passed): on, the robot
// walks there and turns round; off, it arrives facing along the corridor, a half turn sooner.
TEST(LocalPlanner, AClustersViewpointIsReachedFacingAlongThePathWithFaceClusterOff) {
  PlanOptions po;
  po.face_cluster = true;
  const ArriveRun on = run_arrive(po, Eigen::Vector3f(2, 0, 0), M_PI);
  po.face_cluster = false;
  const ArriveRun off = run_arrive(po, Eigen::Vector3f(2, 0, 0), M_PI);
  ASSERT_EQ(on.status, LocalPlanStatus::kNewTrajectory);
  ASSERT_EQ(off.status, LocalPlanStatus::kNewTrajectory);
  EXPECT_LT((on.end_m - Eigen::Vector3d(2, 0, 0)).head<2>().norm(), 0.3);
  EXPECT_LT((off.end_m - Eigen::Vector3d(2, 0, 0)).head<2>().norm(), 0.3);
  EXPECT_GT(std::abs(std::remainder(on.end_yaw_rad, 2 * M_PI)), M_PI - 0.2);  // facing back
  EXPECT_LT(std::abs(std::remainder(off.end_yaw_rad, 2 * M_PI)), 0.35);       // along the path
  // A half turn at most 1 rad/s (0.8 of it in the re-timing) takes over 3 s.
  EXPECT_LT(off.duration_s, on.duration_s - 2.0);
}

namespace {
// PlanOptions::tsp_max_clusters: Stage 1 schedules at most this many clusters, the nearest (graph
// distance from the robot); the rest wait for a later cycle. One scan of the corridor leaves
// more clusters than the default 12 (its under-observed floor between the rings).
size_t scheduled(int tsp_max_clusters, size_t* n_clusters) {
  const World w = corridor();
  Harness h;
  EXPECT_TRUE(scan_from(h, w, Eigen::Vector3f(0, 0, 0)));
  *n_clusters = h.clusters.clusters().size();
  const auto view = h.map.view();
  PlanOptions po;
  po.tsp_max_clusters = tsp_max_clusters;
  LocalPlanner lp(RobotModel{}, po, 0.1);
  const LocalPlanResult r = lp.plan(input(h, view, Eigen::Vector3f(0, 1.5f, 0), 0.0));
  EXPECT_EQ(r.status, LocalPlanStatus::kNewTrajectory) << r.replan_reason;
  if (!r.cluster_order.empty()) {
    EXPECT_EQ(r.target_cluster, r.cluster_order[0]);
  }
  return r.cluster_order.size();
}
}  // namespace

TEST(LocalPlanner, StageOneSchedulesAtMostTspMaxClusters) {
  size_t n = 0;
  ASSERT_EQ(scheduled(PlanOptions{}.tsp_max_clusters, &n), 12u);
  ASSERT_GT(n, 12u);
  EXPECT_EQ(scheduled(1000, &n), n);  // every cluster
  EXPECT_EQ(scheduled(3, &n), 3u);
}

// PlanOptions::floor_first. A 2.4 m corridor rising by 5 cm steps (7 deg, a ramp to the
// graph) from x = 0 to a level 1.2 m up at x = 9.6, seen from the floor and from the upper level:
// frontier clusters on both. On, Stage 1 schedules the robot's floor's clusters only while any
// is left; off, both levels'.
namespace {
World ramp_corridor() {
  World w;
  w.add({-8, -1.2f, -0.2f}, {0, 1.2f, 0});
  w.stairs(0.0f, -1.2f, 1.2f, 0.0f, 24, 0.05f, 0.4f);
  w.add({9.6f, -1.2f, 1.0f}, {20, 1.2f, 1.2f});
  w.add({-8, -1.4f, 0}, {20, -1.2f, 4.0f});
  w.add({-8, 1.2f, 0}, {20, 1.4f, 4.0f});
  return w;
}

// Stage 1's order with the robot on the floor at (-2, 0); without the floor's clusters if
// drop_floor. *up: the ids of the clusters up the ramp or on the upper level (centroid > 0.6 m).
std::vector<int32_t> floor_first_order(bool on, bool drop_floor, std::vector<int32_t>* up,
                                       bool stale = false) {
  Harness h;
  const World w = ramp_corridor();
  h.observe(w, {-2.0f, 0, 0}, 40000, 1);
  h.observe(w, {4.0f, 0, 0.5f}, 40000, 2);
  h.observe(w, {11.0f, 0, 1.2f}, 40000, 3);
  std::vector<storey::core::graph::FrontierCluster> clusters;
  up->clear();
  for (const auto& c : h.clusters.clusters()) {
    const bool is_up = c.centroid_m.z() > 0.6f;
    if (drop_floor && !is_up) continue;
    if (is_up) up->push_back(c.id);
    clusters.push_back(c);
  }
  const auto view = h.map.view();
  PlanOptions po;
  po.floor_first = on;
  po.stale_floor_s = 5.0;
  LocalPlanner lp(RobotModel{}, po, 0.1);
  LocalPlanInput in = input(h, view, Eigen::Vector3f(-2.0f, 0, 0), 0.0);
  in.clusters = &clusters;
  LocalPlanResult r = lp.plan(in);
  if (stale) {  // the graph has not grown for stale_floor_s: replanned then (periodic)
    in.t_s = 6.0;
    r = lp.plan(in);
  }
  EXPECT_EQ(r.status, LocalPlanStatus::kNewTrajectory) << r.replan_reason;
  return r.cluster_order;
}
}  // namespace

TEST(LocalPlanner, WithFloorFirstStageOneSchedulesTheRobotsFloorFirst) {
  std::vector<int32_t> up;
  auto n_up = [&](const std::vector<int32_t>& order) {
    return std::count_if(order.begin(), order.end(), [&](int32_t id) {
      return std::find(up.begin(), up.end(), id) != up.end();
    });
  };
  const std::vector<int32_t> off = floor_first_order(false, false, &up);
  ASSERT_GE(up.size(), 2u);
  EXPECT_GT(n_up(off), 0);  // off: the upper level's clusters are scheduled with the floor's
  const std::vector<int32_t> on = floor_first_order(true, false, &up);
  ASSERT_FALSE(on.empty());
  EXPECT_EQ(n_up(on), 0);  // on: the floor's only
  EXPECT_LT(on.size(), off.size());
  // No cluster left on the floor: the others are scheduled.
  const std::vector<int32_t> rest = floor_first_order(true, true, &up);
  EXPECT_EQ(size_t(n_up(rest)), up.size());
  EXPECT_EQ(rest.size(), up.size());
  // The graph stopped growing with the floor's clusters left (they do not resolve): the others
  // go first, alone.
  const std::vector<int32_t> stale = floor_first_order(true, false, &up, true);
  ASSERT_FALSE(stale.empty());
  EXPECT_EQ(size_t(n_up(stale)), stale.size());
}
