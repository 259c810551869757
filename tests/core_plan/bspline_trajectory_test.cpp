#include "core/plan/bspline_trajectory.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include <Eigen/Geometry>

#include "core/plan/voxel_astar.hpp"
#include "tests/core_plan/voxel_world.hpp"

namespace storey::core::plan {
namespace {

using storey::test::aabb;
using storey::test::World;

// Independent of FCL: no occupied voxel's surface point above the ground rule lies inside the
// (unpadded) body box at any dense sample.
int count_body_intrusions(const map::MapView& view, const BsplineTrajectory& t,
                          const RobotModel& robot, double dt = 0.01) {
  int hits = 0;
  std::vector<Eigen::Vector3f> vox;
  for (double s = t.t_start(); s <= t.t_end(); s += dt) {
    const BodyPose p = t.pose(s);
    const Eigen::Matrix3d r = (Eigen::AngleAxisd(p.yaw_rad, Eigen::Vector3d::UnitZ()) *
                               Eigen::AngleAxisd(-p.pitch_rad, Eigen::Vector3d::UnitY()))
                                  .toRotationMatrix();
    vox.clear();
    view.occupied_in_box(p.foot_m.cast<float>(), Eigen::Vector3f(0.6f, 0.6f, 0.8f), vox);
    for (const auto& c : vox) {
      Eigen::Vector3d q = c.cast<double>();
      q.z() = view.surface_height_m(view.key_of(c)).value_or(c.z());
      const Eigen::Vector3d l = r.transpose() * (q - p.foot_m);
      if (l.z() < robot.step_height_m) continue;  // ground
      if (std::abs(l.x()) < 0.5 * robot.body_length_m &&
          std::abs(l.y()) < 0.5 * robot.body_width_m && l.z() < robot.body_height_m)
        ++hits;
    }
  }
  return hits;
}

// tol: relative excess allowed (a re-timed curve meets its limits exactly at its samples only).
void expect_limits(const BsplineTrajectory& t, const RobotModel& robot, double tol = 1e-9) {
  double vmax = 0, amax = 0, wmax = 0;
  for (double s = t.t_start(); s <= t.t_end(); s += 0.005) {
    const TrajectorySample q = t.sample(s);
    vmax = std::max(vmax, q.v_mps.head<2>().norm());
    amax = std::max(amax, q.a_mps2.head<2>().norm());
    wmax = std::max(wmax, std::abs(q.yaw_rate_rps));
  }
  EXPECT_LE(vmax, robot.max_speed_mps * (1 + tol));
  EXPECT_LE(amax, robot.max_accel_mps2 * (1 + tol));
  EXPECT_LE(wmax, robot.max_yaw_rate_rps * (1 + tol));
  EXPECT_LE(t.speed_bound_mps(), robot.max_speed_mps * (1 + tol));
  EXPECT_GT(vmax, 0.3 * robot.max_speed_mps);  // and not uselessly slow
}

// An L-shaped walk, 4 m then a right angle and 4 m, built in an empty map with `options`.
const std::vector<Eigen::Vector3d> kEll{{0, 0, 0}, {4, 0, 0}, {4, 4, 0}};
TrajectoryResult build_ell(const RobotModel& robot, const TrajectoryOptions& options = {}) {
  map::TraversabilityMap empty;
  CollisionChecker cc(robot, 0.1);
  return TrajectoryBuilder(robot, options).build(empty.view(), cc, kEll, 0.0, std::nullopt, 0.0);
}

// Both timings: one knot interval for the whole curve, and the curve re-timed.
class BsplineTiming : public ::testing::TestWithParam<bool> {};

TEST_P(BsplineTiming, LimitsAndEndpointsOnRandomPolylines) {
  // An empty map: no support (no shortcuts) and nothing to hit; the fit alone is tested.
  map::TraversabilityMap empty;
  RobotModel robot;
  CollisionChecker cc(robot, 0.1);
  TrajectoryBuilder tb(robot, TrajectoryOptions{.retime = GetParam()});
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> step(-1.5, 1.5), yaw(-M_PI, M_PI);
  for (int trial = 0; trial < 20; ++trial) {
    std::vector<Eigen::Vector3d> path{{0, 0, 0}};
    for (int k = 0; k < 2 + trial % 6; ++k)
      path.push_back(path.back() + Eigen::Vector3d(step(rng), step(rng), 0.05 * step(rng)));
    const double y0 = yaw(rng), y1 = yaw(rng);
    const TrajectoryResult r = tb.build(empty.view(), cc, path, y0, y1, 10.0);
    ASSERT_EQ(r.status, TrajectoryStatus::kOk) << to_string(r.status);
    const BsplineTrajectory& t = r.trajectory;
    EXPECT_DOUBLE_EQ(t.t_start(), 10.0);
    const TrajectorySample a = t.sample(t.t_start()), b = t.sample(t.t_end());
    EXPECT_NEAR((a.p_m - path.front()).norm(), 0, 1e-9);
    EXPECT_NEAR((b.p_m - path.back()).norm(), 0, 1e-9);
    EXPECT_NEAR(a.v_mps.norm(), 0, 1e-9);  // starts and ends at rest
    EXPECT_NEAR(b.v_mps.norm(), 0, 1e-9);
    EXPECT_NEAR(std::remainder(a.yaw_rad - y0, 2 * M_PI), 0, 1e-9);
    EXPECT_NEAR(std::remainder(b.yaw_rad - y1, 2 * M_PI), 0, 1e-9);
    EXPECT_EQ(t.retimed(), GetParam());
    expect_limits(t, robot, GetParam() ? 0.02 : 1e-9);
    // Sampling outside the time range clamps to the ends.
    EXPECT_NEAR((t.sample(-5).p_m - path.front()).norm(), 0, 1e-9);
    EXPECT_NEAR((t.sample(1e9).p_m - path.back()).norm(), 0, 1e-9);
  }
}

// One knot interval for the whole curve must not hold it far below the limits: a straight walk
// reaches v_max (the halfway points next to the rest triples; it peaked at 0.71 v_max), a half
// turn in place reaches most of the yaw-rate limit (it turned at 0.35 of it) and a turn on the
// way does not slow the walk after it.
TEST_P(BsplineTiming, StraightWalksAndTurnsInPlaceUseTheLimits) {
  map::TraversabilityMap empty;
  RobotModel robot;
  CollisionChecker cc(robot, 0.1);
  TrajectoryBuilder tb(robot, TrajectoryOptions{.retime = GetParam()});
  const double tol = GetParam() ? 0.02 : 1e-9;
  auto peak = [](const BsplineTrajectory& t) {
    double v = 0, w = 0;
    for (double s = t.t_start(); s <= t.t_end(); s += 0.005) {
      v = std::max(v, t.sample(s).v_mps.head<2>().norm());
      w = std::max(w, std::abs(t.sample(s).yaw_rate_rps));
    }
    return std::pair{v, w};
  };
  const std::vector<Eigen::Vector3d> line{{0, 0, 0}, {6, 0, 0}};
  const TrajectoryResult walk = tb.build(empty.view(), cc, line, 0.0, 0.0, 0.0);
  ASSERT_EQ(walk.status, TrajectoryStatus::kOk);
  expect_limits(walk.trajectory, robot, tol);
  EXPECT_GT(peak(walk.trajectory).first, 0.95 * robot.max_speed_mps);
  // 6 m from rest to rest: no faster than v_max with the acceleration ramps, not much slower.
  EXPECT_LT(walk.trajectory.duration(), 6.0 / robot.max_speed_mps + 3.0);

  const std::vector<Eigen::Vector3d> here{{0, 0, 0}};
  const TrajectoryResult turn = tb.build(empty.view(), cc, here, 0.0, M_PI, 0.0);
  ASSERT_EQ(turn.status, TrajectoryStatus::kOk);
  EXPECT_LE(peak(turn.trajectory).second, robot.max_yaw_rate_rps * (1 + tol));
  EXPECT_GT(peak(turn.trajectory).second, 0.8 * robot.max_yaw_rate_rps);
  EXPECT_LT(turn.trajectory.duration(), 2.0 * M_PI / robot.max_yaw_rate_rps);

  // Facing away from the walk: the turn at the start, then the walk at v_max.
  const TrajectoryResult back = tb.build(empty.view(), cc, line, M_PI, 0.0, 0.0);
  ASSERT_EQ(back.status, TrajectoryStatus::kOk);
  expect_limits(back.trajectory, robot, tol);
  EXPECT_GT(peak(back.trajectory).first, 0.95 * robot.max_speed_mps);
}

INSTANTIATE_TEST_SUITE_P(UniformAndRetimed, BsplineTiming, ::testing::Bool(),
                         [](const auto& info) { return info.param ? "Retimed" : "Uniform"; });

// TrajectoryOptions::retime: the L-shaped walk whose one right-angle corner held every metre of
// it to 0.84 v_max (one knot interval) keeps its shape to the millimetre, walks its straights at
// the speed limit, slows for the corner only and arrives sooner, within every limit.
TEST(BsplineTrajectory, RetimingKeepsTheCurveAndWalksItsStraightsAtTheLimit) {
  RobotModel robot;
  const std::vector<Eigen::Vector3d>& ell = kEll;
  const TrajectoryResult plain = build_ell(robot);
  const TrajectoryResult fast = build_ell(robot, TrajectoryOptions{.retime = true});
  ASSERT_EQ(plain.status, TrajectoryStatus::kOk);
  ASSERT_EQ(fast.status, TrajectoryStatus::kOk);
  const BsplineTrajectory &p = plain.trajectory, &f = fast.trajectory;
  ASSERT_TRUE(f.retimed());
  ASSERT_FALSE(p.retimed());
  double peak = 0, at_corner = 1e9, corner_gap = 1e9, off_curve = 0;
  for (double s = f.t_start(); s <= f.t_end(); s += 0.01) {
    const TrajectorySample q = f.sample(s);
    peak = std::max(peak, q.v_mps.head<2>().norm());
    const double gap = (q.p_m - ell[1]).head<2>().norm();
    if (gap < corner_gap) corner_gap = gap, at_corner = q.v_mps.head<2>().norm();
    double nearest = 1e9;  // the plain curve, densely sampled
    for (double r = p.t_start(); r <= p.t_end(); r += 0.002)
      nearest = std::min(nearest, (p.sample(r).p_m - q.p_m).norm());
    off_curve = std::max(off_curve, nearest);
  }
  EXPECT_LT(off_curve, 2e-3);
  EXPECT_GT(peak, 0.95 * robot.max_speed_mps);
  EXPECT_LT(at_corner, 0.8 * peak);
  EXPECT_LT(f.duration(), 0.85 * p.duration());
  expect_limits(f, robot, 0.02);
  EXPECT_NEAR((f.sample(f.t_end()).p_m - ell.back()).norm(), 0, 1e-9);
  EXPECT_NEAR(f.sample(f.t_start()).v_mps.norm(), 0, 1e-9);
  EXPECT_NEAR(f.sample(f.t_end()).v_mps.norm(), 0, 1e-9);
  // The reported velocity is the derivative of the reported position.
  for (double s = f.t_start() + 0.05; s < f.t_end() - 0.05; s += 0.37) {
    const Eigen::Vector3d fd = (f.sample(s + 1e-4).p_m - f.sample(s - 1e-4).p_m) / 2e-4;
    EXPECT_NEAR((fd - f.sample(s).v_mps).norm(), 0, 0.02) << "t " << s;
  }
}

// TrajectoryOptions::grade_corners: one right-angle corner held the whole L-shaped walk (one knot
// interval) to 0.84 v_max; with the spacing halved into the corner the straight parts reach v_max
// and the curve slows for the corner only, within every limit.
TEST(BsplineTrajectory, GradedCornersLetTheStraightsReachTheSpeedLimit) {
  RobotModel robot;
  const std::vector<Eigen::Vector3d>& ell = kEll;
  auto peak_speed = [](const BsplineTrajectory& t) {
    double v = 0;
    for (double s = t.t_start(); s <= t.t_end(); s += 0.005)
      v = std::max(v, t.sample(s).v_mps.head<2>().norm());
    return v;
  };
  const TrajectoryResult plain = build_ell(robot);
  const TrajectoryResult graded = build_ell(robot, TrajectoryOptions{.grade_corners = true});
  ASSERT_EQ(plain.status, TrajectoryStatus::kOk);
  ASSERT_EQ(graded.status, TrajectoryStatus::kOk);
  EXPECT_LT(peak_speed(plain.trajectory), 0.9 * robot.max_speed_mps);  // 0.84
  EXPECT_GT(peak_speed(graded.trajectory), 0.95 * robot.max_speed_mps);
  EXPECT_LT(graded.trajectory.duration(), 0.95 * plain.trajectory.duration());  // 12.0 s, 13.1 s
  expect_limits(graded.trajectory, robot);
  const BsplineTrajectory& t = graded.trajectory;
  EXPECT_NEAR((t.sample(t.t_end()).p_m - ell.back()).norm(), 0, 1e-9);
  // It hugs the corner at least as close as the plain curve.
  auto corner_gap = [&](const BsplineTrajectory& u) {
    double d = 1e9;
    for (double s = u.t_start(); s <= u.t_end(); s += 0.005)
      d = std::min(d, (u.sample(s).p_m - ell[1]).head<2>().norm());
    return d;
  };
  EXPECT_LE(corner_gap(t), corner_gap(plain.trajectory));
}

// Turning in place: the control points differ by a millimetre in x and a centimetre of surface
// noise in z. The body's pitch stays level (it was atan(10 / 1) = 84 deg, which put the box into
// the next stair riser in the look-ahead).
TEST(BsplineTrajectory, TurningInPlaceKeepsTheBodyLevel) {
  std::vector<Eigen::Vector3d> c;
  std::vector<double> y;
  for (int k = 0; k < 8; ++k) {
    c.emplace_back(0.001 * k, 0.0, 0.01 * (k % 2));
    y.push_back(0.4 * k);
  }
  const BsplineTrajectory t(c, y, 0.5, 0.0);
  for (double s = t.t_start(); s <= t.t_end(); s += 0.05) EXPECT_EQ(t.pose(s).pitch_rad, 0.0) << s;
  // Walking up a 10 deg ramp still reads its pitch.
  std::vector<Eigen::Vector3d> r;
  for (int k = 0; k < 8; ++k) r.emplace_back(0.2 * k, 0.0, 0.2 * k * std::tan(10 * M_PI / 180));
  const BsplineTrajectory u(r, std::vector<double>(8, 0.0), 0.5, 0.0);
  EXPECT_NEAR(u.pose(0.5 * (u.t_start() + u.t_end())).pitch_rad, 10 * M_PI / 180, 1e-6);
}

// TrajectoryBuilder::build with a start velocity (PlanOptions::start_at_speed): the curve leaves
// its first point along the velocity at its speed, within every limit, and arrives sooner than
// from rest. A velocity across the path's first leg: the curve still leaves along it, as fast as
// the bend right after the start allows (below the robot's speed). Without re-timing the
// velocity is ignored (one knot interval has no start speed to give).
TEST(BsplineTrajectory, ACurveStartedAtSpeedLeavesAlongTheVelocity) {
  const RobotModel robot;
  map::TraversabilityMap empty;
  CollisionChecker cc(robot, 0.1);
  TrajectoryBuilder tb(robot, TrajectoryOptions{.retime = true});
  const TrajectoryResult rest = tb.build(empty.view(), cc, kEll, 0.0, std::nullopt, 0.0);
  const TrajectoryResult go =
      tb.build(empty.view(), cc, kEll, 0.0, std::nullopt, 0.0, Eigen::Vector2d(0.8, 0.0));
  ASSERT_EQ(go.status, TrajectoryStatus::kOk);
  const BsplineTrajectory& t = go.trajectory;
  const TrajectorySample s0 = t.sample(t.t_start());
  EXPECT_NEAR((s0.p_m - kEll[0]).norm(), 0, 1e-9);
  EXPECT_NEAR(s0.v_mps.x(), 0.8, 1e-3);
  EXPECT_NEAR(s0.v_mps.y(), 0.0, 1e-6);
  EXPECT_NEAR(go.start_speed_mps, 0.8, 1e-3);
  EXPECT_NEAR(rest.start_speed_mps, 0.0, 1e-9);
  expect_limits(t, robot, 0.02);
  EXPECT_LT(t.duration(), rest.trajectory.duration() - 0.3);
  EXPECT_NEAR((t.sample(t.t_end()).p_m - kEll.back()).norm(), 0, 1e-9);
  EXPECT_NEAR(t.sample(t.t_end()).v_mps.norm(), 0, 1e-9);
  for (double s = t.t_start() + 1e-3; s < t.t_start() + 1.0; s += 0.1) {
    const Eigen::Vector3d fd = (t.sample(s + 1e-4).p_m - t.sample(s - 1e-4).p_m) / 2e-4;
    EXPECT_NEAR((fd - t.sample(s).v_mps).norm(), 0, 0.02) << "t " << s;
  }

  const Eigen::Vector2d across(0.0, -0.8);
  const TrajectoryResult bend =
      tb.build(empty.view(), cc, kEll, -M_PI / 2, std::nullopt, 0.0, across);
  ASSERT_EQ(bend.status, TrajectoryStatus::kOk);
  const Eigen::Vector3d v0 = bend.trajectory.sample(0.0).v_mps;
  EXPECT_GT(bend.start_speed_mps, 0.05);
  EXPECT_LT(bend.start_speed_mps, 0.75);
  EXPECT_NEAR(v0.head<2>().normalized().dot(across.normalized()), 1.0, 1e-6);
  expect_limits(bend.trajectory, robot, 0.02);

  TrajectoryBuilder uniform(robot);
  const TrajectoryResult u =
      uniform.build(empty.view(), cc, kEll, 0.0, std::nullopt, 0.0, Eigen::Vector2d(0.8, 0.0));
  EXPECT_NEAR(u.start_speed_mps, 0.0, 1e-9);
}

TEST(BsplineTrajectory, BadInput) {
  map::TraversabilityMap empty;
  CollisionChecker cc(RobotModel{}, 0.1);
  TrajectoryBuilder tb(RobotModel{});
  std::vector<Eigen::Vector3d> none;
  EXPECT_EQ(tb.build(empty.view(), cc, none, 0, std::nullopt, 0).status,
            TrajectoryStatus::kBadInput);
  std::vector<Eigen::Vector3d> nan_path{{0, 0, 0}, {std::nan(""), 0, 0}};
  EXPECT_EQ(tb.build(empty.view(), cc, nan_path, 0, std::nullopt, 0).status,
            TrajectoryStatus::kBadInput);
  EXPECT_EQ(tb.build(empty.view(), cc, kEll, 0, std::nullopt, 0, Eigen::Vector2d(NAN, 0)).status,
            TrajectoryStatus::kBadInput);
  std::vector<Eigen::Vector3d> one{{1, 2, 0}};
  const TrajectoryResult r = tb.build(empty.view(), cc, one, 0, M_PI / 2, 0);  // turn in place
  ASSERT_EQ(r.status, TrajectoryStatus::kOk);
  EXPECT_NEAR(r.trajectory.sample(r.trajectory.t_end()).yaw_rad, M_PI / 2, 1e-9);
  EXPECT_NEAR((r.trajectory.sample(0.3).p_m - one[0]).norm(), 0, 1e-9);
}

World room_with_pillars() {
  World w;
  w.add(aabb({-4, -3, -0.2f}, {6, 3, 0}));
  w.add(aabb({-4, -3.2f, 0}, {6, -3, 2.5f}));
  w.add(aabb({-4, 3, 0}, {6, 3.2f, 2.5f}));
  w.add(aabb({0.8f, -0.6f, 0}, {1.4f, 0.6f, 2.5f}));  // pillar on the straight line
  w.add(aabb({3.0f, 0.4f, 0}, {3.4f, 3.0f, 1.0f}));   // a counter from the wall
  return w;
}

TEST(BsplineTrajectory, AStarPathToSmoothCollisionFreeTrajectory) {
  map::TraversabilityMap m;
  storey::test::scan_world(
      m, room_with_pillars(),
      {{-2, 0, 0.5f}, {2.2f, -1.5f, 0.5f}, {4.5f, 1.5f, 0.5f}, {2, 1.5f, 0.5f}});
  const map::MapView view = m.view();
  RobotModel robot;
  VoxelAStar astar;
  const VoxelPath vp = astar.plan(view, {-2, 0, 0}, {4.5, 1.5, 0});
  ASSERT_EQ(vp.status, VoxelAStarStatus::kOk) << to_string(vp.status);
  CollisionChecker cc(robot, view.voxel_size_m());
  TrajectoryBuilder tb(robot);
  const TrajectoryResult r = tb.build(view, cc, vp.points_m, 0.0, M_PI / 2, 0.0);
  ASSERT_TRUE(r.status == TrajectoryStatus::kOk || r.status == TrajectoryStatus::kPolyline)
      << to_string(r.status) << " hit at t=" << r.hit.t_s << " voxel " << r.hit.voxel_m.transpose()
      << " pose " << r.trajectory.pose(r.hit.t_s).foot_m.transpose() << " yaw "
      << r.trajectory.pose(r.hit.t_s).yaw_rad << " waypoints " << r.waypoints_m.size();
  EXPECT_LT(r.waypoints_m.size(), vp.points_m.size() / 3);  // shortcutting pruned the path
  EXPECT_FALSE(cc.check_ahead(
                     view, [&](double t) { return r.trajectory.pose(t); }, 0.0,
                     r.trajectory.duration(), 0.01)
                   .collides);
  EXPECT_EQ(count_body_intrusions(view, r.trajectory, robot), 0);
  expect_limits(r.trajectory, robot);
  EXPECT_NEAR((r.trajectory.sample(r.trajectory.t_end()).p_m - vp.points_m.back()).norm(), 0, 1e-9);
}

TEST(BsplineTrajectory, PathThroughAnObstacleIsReported) {
  map::TraversabilityMap m;
  storey::test::scan_world(m, room_with_pillars(), {{-2, 0, 0.5f}, {2.5f, 0, 0.5f}});
  RobotModel robot;
  CollisionChecker cc(robot, 0.1);
  TrajectoryBuilder tb(robot, TrajectoryOptions{.shortcut = false});
  std::vector<Eigen::Vector3d> through{{-2, 0, 0}, {0, 0, 0}, {2.5, 0, 0}};
  const TrajectoryResult r = tb.build(m.view(), cc, through, 0.0, std::nullopt, 0.0);
  EXPECT_EQ(r.status, TrajectoryStatus::kCollision);
  EXPECT_TRUE(r.hit.collides);
}

World stair_world() {
  World w;
  w.add(aabb({-3, -1.5f, -0.2f}, {1, 1.5f, 0}));
  w.stairs(1, -0.8f, 0.8f, 0, 6, 0.15f, 0.30f);
  w.add(aabb({2.8f, -1.5f, -0.2f}, {6, 1.5f, 0.9f}));
  w.add(aabb({-3, -1.7f, 0}, {6, -1.5f, 3.0f}));
  w.add(aabb({-3, 1.5f, 0}, {6, 1.7f, 3.0f}));
  return w;
}

// The stair world scanned from the lower floor, the flight and the landing.
void scan_stairs(map::TraversabilityMap& m) {
  storey::test::scan_world(
      m, stair_world(),
      {{-1, 0, 0.5f}, {0.5f, 0, 0.5f}, {1.9f, 0, 0.95f}, {4, 0, 1.4f}, {3, 0, 1.4f}});
}

TEST(BsplineTrajectory, ClimbsStairsWithoutCollision) {
  map::TraversabilityMap m;
  scan_stairs(m);
  const map::MapView view = m.view();
  RobotModel robot;
  VoxelAStar astar(VoxelAStarOptions{.reachable_only = false});
  const VoxelPath vp = astar.plan(view, {-1, 0, 0}, {4, 0, 0.9});
  ASSERT_EQ(vp.status, VoxelAStarStatus::kOk) << to_string(vp.status);
  CollisionChecker cc(robot, view.voxel_size_m());
  TrajectoryBuilder tb(robot, TrajectoryOptions{.reachable_only = false});
  const TrajectoryResult r = tb.build(view, cc, vp.points_m, 0.0, std::nullopt, 0.0);
  ASSERT_TRUE(r.status == TrajectoryStatus::kOk || r.status == TrajectoryStatus::kPolyline)
      << to_string(r.status) << " hit at t=" << r.hit.t_s << " voxel " << r.hit.voxel_m.transpose();
  EXPECT_NEAR(r.trajectory.sample(r.trajectory.t_end()).p_m.z(), vp.points_m.back().z(), 1e-9);
  EXPECT_EQ(count_body_intrusions(view, r.trajectory, robot), 0);
  expect_limits(r.trajectory, robot);
}

// Down the same flight from its fifth tread, facing up it (a robot that climbed part of it): the
// body walks down backwards, still facing up, and turns round only on the lower floor. From the
// landing, a path down the flight is walked forwards as before (the robot turns on the landing).
TEST(BsplineTrajectory, WalksDownAFlightItStandsOnBackwards) {
  map::TraversabilityMap m;
  scan_stairs(m);
  const map::MapView view = m.view();
  RobotModel robot;
  VoxelAStar astar(VoxelAStarOptions{.reachable_only = false});
  CollisionChecker cc(robot, view.voxel_size_m());
  TrajectoryBuilder tb(robot, TrajectoryOptions{.reachable_only = false});
  for (const Eigen::Vector3d& start :
       {Eigen::Vector3d(2.35, 0, 0.75), Eigen::Vector3d(4, 0, 0.9)}) {
    const bool on_flight = start.x() < 2.8;
    const VoxelPath vp = astar.plan(view, start, {-1, 0, 0});
    ASSERT_EQ(vp.status, VoxelAStarStatus::kOk) << to_string(vp.status);
    const TrajectoryResult r = tb.build(view, cc, vp.points_m, 0.0, std::nullopt, 0.0);
    ASSERT_TRUE(r.status == TrajectoryStatus::kOk || r.status == TrajectoryStatus::kPolyline)
        << to_string(r.status) << " hit at t=" << r.hit.t_s << " voxel "
        << r.hit.voxel_m.transpose();
    int mid_flight = 0;
    for (double t = r.trajectory.t_start(); t <= r.trajectory.t_end(); t += 0.05) {
      const TrajectorySample s = r.trajectory.sample(t);
      if (s.p_m.x() > 1.3 && s.p_m.x() < 2.2) {  // treads 2..4
        ++mid_flight;
        const double facing_up = std::abs(std::remainder(s.yaw_rad, 2 * M_PI));
        if (on_flight)
          EXPECT_LT(facing_up, 0.3) << "t " << t << " x " << s.p_m.x() << " yaw " << s.yaw_rad;
        else
          EXPECT_GT(facing_up, M_PI - 0.3) << "t " << t << " x " << s.p_m.x();
      }
    }
    EXPECT_GT(mid_flight, 5);
    const double end_yaw = r.trajectory.sample(r.trajectory.t_end()).yaw_rad;
    EXPECT_NEAR(std::abs(std::remainder(end_yaw, 2 * M_PI)), M_PI, 0.3);  // facing down the room
    EXPECT_EQ(count_body_intrusions(view, r.trajectory, robot), 0);
    expect_limits(r.trajectory, robot);
  }
}

}  // namespace
}  // namespace storey::core::plan
