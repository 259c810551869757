// The shared escape (core/plan/escape.hpp): out of a corridor narrower than the body's turning
// circle, straight into the room it opens into.
#include "core/plan/escape.hpp"

#include <gtest/gtest.h>

#include "tests/core_plan/voxel_world.hpp"

namespace storey::core::plan {
namespace {

// A 0.6 m corridor along x (x < 0) opening into a 4 x 4 m room (x > 0).
map::TraversabilityMap corridor_into_room() {
  storey::test::World w;
  w.add(storey::test::aabb({-3, -2, -0.2f}, {4, 2, 0}));  // floor
  w.add(storey::test::aabb({-3, -0.5f, 0}, {0, -0.3f, 1.5f}));
  w.add(storey::test::aabb({-3, 0.3f, 0}, {0, 0.5f, 1.5f}));
  w.add(storey::test::aabb({-0.2f, -2, 0}, {0, -0.5f, 1.5f}));  // room wall beside the mouth
  w.add(storey::test::aabb({-0.2f, 0.5f, 0}, {0, 2, 1.5f}));
  w.add(storey::test::aabb({4, -2, 0}, {4.2f, 2, 1.5f}));
  w.add(storey::test::aabb({-0.2f, -2.2f, 0}, {4, -2, 1.5f}));
  w.add(storey::test::aabb({-0.2f, 2, 0}, {4, 2.2f, 1.5f}));
  map::TraversabilityMap m;
  storey::test::scan_world(m, w, {{-0.3f, 0, 0.5f}, {1.5f, 0, 0.5f}, {-1.5f, 0, 0.5f}});
  return m;
}

TEST(Escape, OutOfACorridorTooNarrowToTurnInIntoTheRoom) {
  const map::TraversabilityMap m = corridor_into_room();
  const map::MapView view = m.view();
  const RobotModel robot;
  CollisionChecker checker(robot, view.voxel_size_m());
  const Eigen::Vector3d start(-0.3, 0, 0);
  ASSERT_FALSE(checker.check_poses(view, std::vector<BodyPose>{{start, 0.0, 0.0, 0.0}}).collides);
  EXPECT_FALSE(can_turn_at(checker, view, start, 0.0));
  EXPECT_TRUE(can_turn_at(checker, view, {1.5, 0, 0}, 0.0));

  const auto w = escape_to_turn(checker, view, robot, start, 0.0, 10.0, 1.2);
  ASSERT_TRUE(w.has_value());
  EXPECT_EQ(w->from_m, start);
  EXPECT_GT(w->to_m.x(), 0.2);  // in the room
  EXPECT_LT((w->to_m - start).head<2>().norm(), 1.2 + 1e-9);
  EXPECT_TRUE(can_turn_at(checker, view, w->to_m, 0.0));
  EXPECT_DOUBLE_EQ(w->trajectory.t_start(), 10.0);
  EXPECT_NEAR(w->trajectory.pose(w->trajectory.t_end()).yaw_rad, 0.0, 1e-9);  // yaw kept

  // No turning place within reach: none.
  EXPECT_FALSE(escape_to_turn(checker, view, robot, start, 0.0, 10.0, 0.3).has_value());
  // Where it can turn already, the nearest turning place is a step away (callers check first).
  EXPECT_TRUE(escape_to_turn(checker, view, robot, {1.5, 0, 0}, 0.0, 0.0, 0.5).has_value());
}

// PlanOptions::turn_before_walk: a straight walk for a robot facing elsewhere first turns the body
// on the spot, the shorter way, within the yaw limits, and that turn is checked: in the corridor
// the body cannot turn, so a walk that starts with a turn there is refused, and in the room the
// same walk turns first and then keeps the walk's yaw.
TEST(Escape, AStraightWalkTurnsTheBodyOnTheSpotFirstAndChecksTheTurn) {
  const map::TraversabilityMap m = corridor_into_room();
  const map::MapView view = m.view();
  const RobotModel robot;
  CollisionChecker checker(robot, view.voxel_size_m());
  const auto line = [](Eigen::Vector3d a, Eigen::Vector3d b) {
    std::vector<Eigen::Vector3d> pts;
    for (int j = 0; j <= 10; ++j) pts.push_back(a + (b - a) * (j / 10.0));
    return pts;
  };
  // Along the corridor, facing along it: no turn needed, and the walk passes.
  const auto along = line({-1.5, 0, 0}, {-0.5, 0, 0});
  EXPECT_TRUE(straight_walk(checker, view, robot, along, 0.0, 0.0, 0.05).has_value());
  // Facing across the corridor (yaw kept, as without the turn, the body at -pi/2 is not checked
  // along the way it turns): with the turn it is refused.
  EXPECT_TRUE(straight_walk(checker, view, robot, along, 0.0, 0.0).has_value());
  EXPECT_FALSE(straight_walk(checker, view, robot, along, 0.0, 0.0, 1.2).has_value());
  // In the room, from facing -y (yaw -pi/2) to walk +x: a quarter turn left on the spot first.
  const auto room = line({1.5, 0, 0}, {2.5, 0, 0});
  const auto w = straight_walk(checker, view, robot, room, 0.0, 10.0, -M_PI / 2);
  ASSERT_TRUE(w.has_value());
  const BsplineTrajectory& t = w->trajectory;
  EXPECT_NEAR(t.pose(t.t_start()).yaw_rad, -M_PI / 2, 1e-9);
  EXPECT_NEAR(t.pose(t.t_end()).yaw_rad, 0.0, 1e-9);
  double max_rate = 0, yaw_when_moving = -M_PI;
  for (double s = t.t_start(); s <= t.t_end(); s += 0.01) {
    const TrajectorySample q = t.sample(s);
    max_rate = std::max(max_rate, std::abs(q.yaw_rate_rps));
    EXPECT_GE(q.yaw_rad, -M_PI / 2 - 1e-9);  // the shorter way: never beyond the start
    EXPECT_LE(q.yaw_rad, 1e-9);
    if ((q.p_m - room.front()).head<2>().norm() > 0.1 && yaw_when_moving == -M_PI)
      yaw_when_moving = q.yaw_rad;
  }
  EXPECT_LE(max_rate, 0.5 * robot.max_yaw_rate_rps + 1e-6);
  EXPECT_GT(yaw_when_moving, -0.1);  // turned before it walked a decimetre
  // A few degrees off (under 0.5 rad): no turn on the spot, the walk keeps its yaw from the start
  // (the tracking law turns the body while it walks; on a flight a level box turning on the spot
  // meets the treads).
  const auto slight = straight_walk(checker, view, robot, room, 0.0, 10.0, 0.3);
  ASSERT_TRUE(slight.has_value());
  EXPECT_NEAR(slight->trajectory.pose(slight->trajectory.t_start()).yaw_rad, 0.0, 1e-9);
  // From +3 rad the shorter way to 0 is down through +pi/2, not up past pi.
  const auto back = straight_walk(checker, view, robot, room, 0.0, 10.0, 3.0);
  ASSERT_TRUE(back.has_value());
  EXPECT_NEAR(back->trajectory.pose(back->trajectory.t_end()).yaw_rad, 0.0, 1e-9);
}

// A moving robot comes to rest |v|^2 / (2 a_max) on along its velocity where the body is clear on
// the way (LocalPlanner::brake_start, a new zone-centre drive); none toward a wall it would meet,
// none for a robot all but at rest.
TEST(Escape, AMovingRobotComesToRestStraightAlongItsVelocity) {
  const map::TraversabilityMap m = corridor_into_room();
  const map::MapView view = m.view();
  const RobotModel robot;
  CollisionChecker checker(robot, view.voxel_size_m());
  const auto rest = straight_rest_point(checker, view, robot, {1.5, 0, 0}, 0.0, {0.8, 0.0}, 0.0);
  ASSERT_TRUE(rest.has_value());
  EXPECT_NEAR(rest->x(), 1.5 + 0.8 * 0.8 / (2 * robot.max_accel_mps2), 0.05) << rest->transpose();
  EXPECT_NEAR(rest->y(), 0.0, 1e-9);
  // 0.5 m from the room's far wall (x = 4) at 1 m/s: the body meets it on the way.
  EXPECT_FALSE(straight_rest_point(checker, view, robot, {3.2, 0, 0}, 0.0, {1.0, 0.0}, 0.0));
  EXPECT_FALSE(straight_rest_point(checker, view, robot, {1.5, 0, 0}, 0.0, {0.2, 0.0}, 0.0));
}

// A robot on a curving trajectory comes to rest along that curve, not straight along its
// velocity (the control task brakes on the trajectory it follows): GoalDriver and
// LocalPlanner::brake_start start the next trajectory there. Off the trajectory: kNotOn.
TEST(Escape, AMovingRobotComesToRestAlongTheCurveItFollows) {
  const map::TraversabilityMap m = corridor_into_room();
  const map::MapView view = m.view();
  const RobotModel robot;
  CollisionChecker checker(robot, view.voxel_size_m());
  // A left turn in the room: east along y = -1, then north along x = 2.5.
  std::vector<Eigen::Vector3d> ctrl;
  for (double x = 0.5; x <= 2.01; x += 0.25) ctrl.push_back({x, -1.0, 0.0});
  for (double y = -0.75; y <= 1.01; y += 0.25) ctrl.push_back({2.5, y, 0.0});
  std::vector<double> yaw;
  for (const Eigen::Vector3d& c : ctrl) yaw.push_back(c.y() > -1.0 ? M_PI / 2 : 0.0);
  const BsplineTrajectory traj(ctrl, yaw, 0.25, 0.0);
  // At the start of the turn, moving east at 1.2 m/s: 0.36 m to rest.
  double t = 0;
  while (traj.sample(t).p_m.x() < 2.0) t += 0.01;
  const Eigen::Vector3d foot = traj.sample(t).p_m;
  const Eigen::Vector2d v(1.2, 0.0);
  const RestOnTrajectory on =
      rest_on_trajectory(checker, view, robot, traj, foot, v, t, 0.0, false);
  ASSERT_EQ(on.kind, RestOnTrajectory::Kind::kRest);
  double off = 1e9;  // on the curve ...
  for (double s = traj.t_start(); s <= traj.t_end(); s += 0.01)
    off = std::min(off, (traj.sample(s).p_m - on.pose.foot_m).head<2>().norm());
  EXPECT_LT(off, 0.02);
  EXPECT_GT(on.pose.foot_m.y(), foot.y() + 0.05);  // ... round the turn: north of straight ahead
  const auto straight = straight_rest_point(checker, view, robot, foot, 0.0, v, 0.0);
  ASSERT_TRUE(straight.has_value());
  EXPECT_GT((*straight - on.pose.foot_m).head<2>().norm(), 0.05);
  // Not on the trajectory (1 m beside it), or all but at rest: kNotOn.
  EXPECT_EQ(rest_on_trajectory(checker, view, robot, traj, foot + Eigen::Vector3d(0, 1, 0), v, t,
                               0.0, false)
                .kind,
            RestOnTrajectory::Kind::kNotOn);
  EXPECT_EQ(rest_on_trajectory(checker, view, robot, traj, foot, {0.2, 0.0}, t, 0.0, false).kind,
            RestOnTrajectory::Kind::kNotOn);
}

TEST(Escape, NearestFreeFootStepsAwayFromAWallItOverlaps) {
  const map::TraversabilityMap m = corridor_into_room();
  const map::MapView view = m.view();
  CollisionChecker checker(RobotModel{}, view.voxel_size_m());
  // In the room, yawed along the wall at y = 2 and 0.1 m from it: the box overlaps the wall.
  const BodyPose by_wall{{2.0, 1.9, 0.0}, 0.0, 0.0, 0.0};
  ASSERT_TRUE(checker.check_poses(view, std::vector<BodyPose>{by_wall}).collides);
  const auto f = nearest_free_foot(checker, view, by_wall, 0.3);
  ASSERT_TRUE(f.has_value());
  EXPECT_LT(f->y(), 1.9);
  EXPECT_LE((*f - by_wall.foot_m).norm(), 0.3 + 1e-9);
  BodyPose q = by_wall;
  q.foot_m = *f;
  EXPECT_FALSE(checker.check_poses(view, std::vector<BodyPose>{q}).collides);
  // A free pose is its own answer; one too deep in the wall has none within reach.
  const BodyPose free{{2.0, 0.0, 0.0}, 0.0, 0.0, 0.0};
  EXPECT_EQ(nearest_free_foot(checker, view, free, 0.3).value(), free.foot_m);
  EXPECT_FALSE(nearest_free_foot(checker, view, {{2.0, 2.1, 0.0}, 0.0, 0.0, 0.0}, 0.1));
}

}  // namespace
}  // namespace storey::core::plan
