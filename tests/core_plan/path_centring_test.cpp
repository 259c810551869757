// Stage 3 path shaping before the B-spline (core/plan/path_centring.hpp): centring in passages,
// run-ups before stair flights, and the collision checker's terrain pitch on a flight.
#include "core/plan/path_centring.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "core/plan/collision_checker.hpp"
#include "tests/core_plan/voxel_world.hpp"

using namespace storey::core;
using namespace storey::core::plan;
using Eigen::Vector3d;
using storey::test::aabb;

namespace {

// Floor, and a wall along x = 0 with a 1.0 m door (y in [-0.5, 0.5]).
storey::test::World door_world() {
  storey::test::World w;
  w.add(aabb({-4, -3, -0.2f}, {4, 3, 0}));
  w.add(aabb({-0.05f, -3, 0}, {0.05f, -0.5f, 2.2f}));
  w.add(aabb({-0.05f, 0.5f, 0}, {0.05f, 3, 2.2f}));
  return w;
}

// Floor, and a flight of 10 steps (0.15 m rise, 0.30 m tread) rising along +x from x = 0,
// 1.2 m wide between side walls.
storey::test::World stair_world() {
  storey::test::World w;
  w.add(aabb({-4, -3, -0.2f}, {6, 3, 0}));
  w.stairs(0.0f, -0.6f, 0.6f, 0.0f, 10, 0.15f, 0.30f);
  w.add(aabb({0, -0.72f, 0}, {3, -0.6f, 2.5f}));
  w.add(aabb({0, 0.6f, 0}, {3, 0.72f, 2.5f}));
  return w;
}

}  // namespace

TEST(PathCentring, MovesPointsInADoorToItsMiddle) {
  map::TraversabilityMap m;
  storey::test::scan_world(m, door_world(), {{-1.5f, 0, 0.5f}, {1.5f, 0, 0.5f}});
  const map::MapView view = m.view();
  // A straight path through the door 0.3 m off its middle (0.2 m from the jamb).
  std::vector<Vector3d> path;
  for (double x = -1.5; x <= 1.5 + 1e-9; x += 0.1) path.emplace_back(x, 0.3, 0.0);
  const std::vector<Vector3d> before = path;
  const PathCentringStats st = centre_path(view, path);
  EXPECT_GT(st.moved, 0);
  EXPECT_LE(st.max_shift_m, 0.3 + 1e-9);
  EXPECT_EQ(path.front(), before.front());
  EXPECT_EQ(path.back(), before.back());
  for (size_t i = 0; i < path.size(); ++i)
    if (std::abs(path[i].x()) < 0.1) {
      EXPECT_LT(std::abs(path[i].y()), 0.1) << "point in the door at x " << path[i].x();
    }
  // Far from the wall (open floor, clearance above half the body length) nothing moves.
  for (size_t i = 1; i + 1 < path.size(); ++i)
    if (std::abs(before[i].x()) > 1.0) {
      EXPECT_EQ(path[i], before[i]);
    }
}

// A 10 deg ramp, 1.5 m wide between side walls, and a sparse path along G_real (nodes 1 m
// apart, 0.18 m of rise between them) 0.25 m from the left wall. The ramp's points are centred
// like level ground; before, the rise between them read as a flight and they stayed at the wall.
TEST(PathCentring, RampPointsAreCentredAlongTheGrade) {
  const float a = float(10 * M_PI / 180);
  storey::test::World w;
  w.add(aabb({-4, -3, -0.2f}, {0.05f, 3, 0}));
  w.add(storey::test::ramp(0.0f, -0.75f, 0.75f, 0.0f, 6.0f, a));
  w.add(aabb({0, -0.87f, -0.2f}, {6, -0.75f, 3.0f}));
  w.add(aabb({0, 0.75f, -0.2f}, {6, 0.87f, 3.0f}));
  map::TraversabilityMap m;
  std::vector<Eigen::Vector3f> origins;
  for (float x = -1.0f; x <= 5.0f; x += 1.0f)
    origins.emplace_back(x, 0.0f, std::max(0.0f, x) * std::tan(a) + 0.5f);
  storey::test::scan_world(m, w, origins);
  const map::MapView view = m.view();
  std::vector<Vector3d> path;
  for (int x = -1; x <= 5; ++x) path.emplace_back(x, 0.5, std::max(0, x) * std::tan(double(a)));
  const std::vector<Vector3d> before = path;
  const PathCentringStats st = centre_path(view, path);
  EXPECT_GT(st.moved, 0);
  for (size_t i = 2; i + 2 < path.size(); ++i) {  // on the ramp, away from its ends
    EXPECT_LT(path[i].y(), 0.4) << i << ": " << path[i].transpose();
    EXPECT_NEAR(path[i].z(), before[i].z(), 0.1) << i;  // still on the ramp's surface
  }
}

TEST(PathCentring, FlightIsWalkedOnItsAxisAfterARunUp) {
  map::TraversabilityMap m;
  storey::test::scan_world(m, stair_world(),
                           {{-1.5f, 0, 0.5f}, {-1.0f, 1.5f, 0.5f}, {0.75f, 0, 0.95f}});
  const map::MapView view = m.view();
  // The flight's axis from its foot, hinted diagonally: +x, on the flight's centre line.
  const auto axis = flight_axis(view, {-0.1, 0.3, 0}, Eigen::Vector2d(1, -1).normalized(), 1.0);
  ASSERT_TRUE(axis.has_value());
  EXPECT_GT(axis->dir.x(), std::cos(10 * M_PI / 180)) << axis->dir.transpose();
  EXPECT_NEAR(axis->origin.y() + (0.0 - axis->origin.x()) * axis->dir.y() / axis->dir.x(), 0.0,
              0.12);
  EXPECT_NEAR(axis->width_m, 1.2, 0.25);
  // A path approaching the foot diagonally from the north-west and climbing near the north
  // side wall, ending on the flight.
  std::vector<Vector3d> path = {{-1.2, 1.6, 0},   {-0.8, 1.2, 0},   {-0.4, 0.8, 0},
                                {-0.2, 0.5, 0},   {-0.1, 0.4, 0},   {0.1, 0.4, 0.15},
                                {0.4, 0.35, 0.3}, {0.7, 0.3, 0.45}, {1.0, 0.3, 0.6}};
  const FlightShaping f = shape_flights(view, path);
  if (getenv("STOREY_DEBUG"))
    for (const Vector3d& q : path) printf("  %.3f %.3f %.3f\n", q.x(), q.y(), q.z());
  ASSERT_EQ(f.flights, 1) << f.no_axis << " " << f.no_run_up;
  EXPECT_TRUE(f.end_on_flight);
  EXPECT_NEAR(f.end_yaw_rad, 0.0, 0.2);
  // The flight's points lie on the axis (within 0.15 m of the centre line y = 0) and rise
  // monotonically; the run-up before the foot is level and on the same line.
  size_t foot = 0;
  while (foot + 1 < path.size() && path[foot + 1].z() < 0.08) ++foot;
  ASSERT_GE(foot, 1u);
  for (size_t i = foot - 1; i < path.size(); ++i) {
    EXPECT_LT(std::abs(path[i].y()), 0.15) << i << ": " << path[i].transpose();
    if (i > foot) {
      EXPECT_GE(path[i].z(), path[i - 1].z() - 0.03) << i;
    }
  }
  EXPECT_LT(std::abs(path[foot - 1].z()), 0.05);
  const RobotModel robot;
  EXPECT_NEAR((path[foot] - path[foot - 1]).head<2>().norm(),
              0.5 * robot.body_length_m + robot.body_margin_m, 0.11);
  EXPECT_NEAR(path.back().x(), 1.0, 0.12);
  // A path that stays level is left alone.
  std::vector<Vector3d> level = {{-2, 0, 0}, {-1.5, 0, 0}, {-1, 0, 0}};
  EXPECT_EQ(shape_flights(view, level).flights, 0);
  EXPECT_EQ(level.size(), 3u);
}

// The place to climb from, found from a frontier cluster's nodes beside the flight's foot (one
// off to the side, one at the corner): on the axis (y = 0), facing up (+x), 0.45 m before the
// first riser (x = 0), on the floor. Where no flight is near, none.
TEST(PathCentring, FlightFootStandsOnTheAxisBeforeTheFirstRiser) {
  map::TraversabilityMap m;
  storey::test::scan_world(m, stair_world(), {{-1.5f, 1.0f, 0.5f}, {-1.0f, -1.5f, 0.5f}});
  const map::MapView view = m.view();
  const std::vector<Vector3d> near = {{-0.3, 1.1, 0.0}, {-0.6, -0.9, 0.0}};
  const auto f = flight_foot(view, near, 0.0);
  ASSERT_TRUE(f.has_value());
  EXPECT_NEAR(f->riser_m.x(), 0.0, 0.1) << f->riser_m.transpose();
  EXPECT_NEAR(f->foot_m.x(), -0.45, 0.1) << f->foot_m.transpose();
  EXPECT_NEAR(f->foot_m.y(), 0.0, 0.12) << f->foot_m.transpose();
  EXPECT_NEAR(f->foot_m.z(), 0.0, 0.05);
  EXPECT_NEAR(f->yaw_rad, 0.0, 0.15);
  // Farther back on request; nothing from points out of reach of the flight or a step too high.
  const auto g = flight_foot(view, near, 0.0, 0.7);
  ASSERT_TRUE(g.has_value());
  EXPECT_NEAR(g->foot_m.x(), -0.7, 0.1);
  EXPECT_FALSE(flight_foot(view, {{-3.0, -2.5, 0.0}}, 0.0, 0.45, 1.0).has_value());
  EXPECT_FALSE(flight_foot(view, near, 0.6).has_value());
  // A door, no flight.
  map::TraversabilityMap d;
  storey::test::scan_world(d, door_world(), {{-1.5f, 0, 0.5f}});
  EXPECT_FALSE(flight_foot(d.view(), {{-0.5, 0.0, 0.0}}, 0.0).has_value());
}

TEST(PathCentring, BodyAtRestOnAFlightTakesTheTerrainPitch) {
  map::TraversabilityMap m;
  storey::test::scan_world(m, stair_world(), {{-1.5f, 0, 0.5f}, {0.75f, 0, 0.95f}});
  const map::MapView view = m.view();
  CollisionChecker cc(RobotModel{}, view.voxel_size_m());
  // Standing at the front of the third tread (top 0.45 m, x 0.6..0.9) facing up the flight,
  // level (pitch 0: what a trajectory at rest reports): the fifth tread (0.30 m higher, 0.35 m
  // ahead) would be inside a level box.
  const BodyPose rest{{0.85, 0, 0.45}, 0.0, 0.0, 0.0};
  const auto tp = cc.terrain_pitch(view, rest);
  ASSERT_TRUE(tp.has_value());
  EXPECT_NEAR(*tp, std::atan2(0.15, 0.30), 0.15);
  EXPECT_FALSE(cc.check_poses(view, std::span<const BodyPose>(&rest, 1)).collides);
  std::vector<Eigen::Vector3f> vox;
  for (int i = 0; i < 10; ++i)
    storey::test::fill_voxels(vox, {0.3f * i, -0.6f, -0.1f},
                              {0.3f * (i + 1), 0.6f, 0.15f * (i + 1)});
  EXPECT_TRUE(cc.check_poses(std::span<const BodyPose>(&rest, 1), vox).collides)
      << "scenario: a level box on the flight should touch the treads ahead";
}

TEST(PathCentring, FootOfAFlightIsReachableOnASparseMap) {
  // 0.167 m risers (a 3 m storey in 18), 0.29 m treads, seen by a VLP-16 at 0.44 m while
  // walking toward the flight: the floor right behind the robot is in the LiDAR's blind ring,
  // tread tops are sparse and nosing voxels mix tread and riser points.
  storey::test::World w;
  w.add(aabb({-4, -3, -0.2f}, {8, 3, 0}));
  w.stairs(0.0f, -0.6f, 0.6f, 0.0f, 17, 3.0f / 18, 0.29f);
  w.add(aabb({0, -0.72f, 0}, {5, -0.6f, 2.5f}));
  w.add(aabb({0, 0.6f, 0}, {5, 0.72f, 2.5f}));
  map::TraversabilityMap m;
  uint32_t seed = 1;
  for (float x : {-2.0f, -1.0f, -0.5f})
    for (int r = 0; r < 10; ++r) {
      const Eigen::Vector3f o(x, 0.05f * r - 0.2f, 0.44f);
      m.insert_scan(o, storey::test::scan_vlp16(w, o, 0.1f * r, seed++));
    }
  m.update_traversability();
  const map::MapView view = m.view();
  CollisionChecker cc(RobotModel{}, view.voxel_size_m());
  // Standing level on the floor up to the first riser, facing the flight: the front legs on
  // the first tread tilt the body; nothing collides.
  for (double x = -0.8; x <= 0.0 + 1e-9; x += 0.1) {
    const BodyPose p{{x, 0.0, 0.0}, 0.0, 0.0, 0.0};
    const CollisionHit h = cc.check_poses(view, std::span<const BodyPose>(&p, 1));
    EXPECT_FALSE(h.collides) << "x " << x << " voxel " << h.voxel_m.transpose();
  }
  // The same body 0.5 m into the flight at floor height is inside the treads: still caught.
  const BodyPose inside{{0.5, 0.0, 0.0}, 0.0, 0.0, 0.0};
  EXPECT_TRUE(cc.check_poses(view, std::span<const BodyPose>(&inside, 1)).collides);
}

TEST(PathCentring, VoxelBoxesAreFittedToTheirPoints) {
  // A wall face at x = 2.09: its points fill the voxel [2.0, 2.1) only in its last centimetre.
  map::TraversabilityMap m;
  std::vector<Eigen::Vector3f> pts;
  for (float y = -1.0f; y <= 1.0f; y += 0.02f) {
    for (float z = 0.02f; z < 1.0f; z += 0.02f) pts.emplace_back(2.09f, y, z);
    for (float x = -1.0f; x < 2.08f; x += 0.05f) pts.emplace_back(x, y, -0.005f);  // floor
  }
  for (int rep = 0; rep < 3; ++rep) m.insert_scan(Eigen::Vector3f(0, 0, 0.5f), pts);
  m.update_traversability();
  const map::MapView view = m.view();
  std::vector<map::MapView::VoxelExtent> ext;
  view.occupied_extents_in_box({2.05f, 0.05f, 0.45f}, {0.01f, 0.01f, 0.01f}, ext);
  ASSERT_EQ(ext.size(), 1u);
  EXPECT_NEAR(ext[0].centre_m.x(), 2.09f, 0.015f);
  EXPECT_LT(ext[0].half_m.x(), 0.025f);
  EXPECT_NEAR(ext[0].half_m.y(), 0.05f, 0.02f);  // spread over the voxel along the face
  // The body 3 cm short of the face (its box, margin included, ends at 2.06) does not collide;
  // 3 cm into it, it does.
  CollisionChecker cc(RobotModel{}, view.voxel_size_m());
  const RobotModel robot;
  const double front = 0.5 * robot.body_length_m + robot.body_margin_m;
  const BodyPose near{{2.06 - front, 0.0, 0.0}, 0.0, 0.0, 0.0};
  const BodyPose into{{2.12 - front, 0.0, 0.0}, 0.0, 0.0, 0.0};
  EXPECT_FALSE(cc.check_poses(view, std::span<const BodyPose>(&near, 1)).collides);
  EXPECT_TRUE(cc.check_poses(view, std::span<const BodyPose>(&into, 1)).collides);
}

namespace {
// A U-shaped return stair as in the teaching building (0.168 m risers, 0.29 m treads, 1.2 m
// flights 0.2 m apart): flight 1 rises along +x from x = 0 to a landing (x 2.32..3.72, top
// 1.516 m), flight 2 runs back along -x from the landing, beside flight 1 (y 0.8..2.0).
storey::test::World u_stair_world() {
  storey::test::World w;
  const float rise = 0.168f, run = 0.29f;
  w.add(aabb({-4, -3, -0.2f}, {6, 4, 0}));
  w.stairs(0.0f, -0.6f, 0.6f, 0.0f, 8, rise, run);
  w.add(aabb({2.32f, -0.6f, -0.2f}, {3.72f, 2.0f, 9 * rise}));  // the landing
  for (int k = 0; k < 9; ++k)  // flight 2: tread k from the landing's edge back along -x
    w.add(aabb({2.32f - (k + 1) * run, 0.8f, -0.2f}, {2.32f - k * run, 2.0f, (10 + k) * rise}));
  w.add(aabb({-0.29f, -0.72f, 0}, {3.84f, -0.6f, 4.2f}));  // outer walls
  w.add(aabb({-0.29f, 2.0f, 0}, {3.84f, 2.12f, 4.2f}));
  w.add(aabb({-0.29f, 0.6f, 0}, {2.32f, 0.8f, 4.2f}));    // the wall between the flights
  w.add(aabb({3.72f, -0.72f, 0}, {3.84f, 2.12f, 4.2f}));  // the landing's end wall
  return w;
}
}  // namespace

// On the landing after climbing flight 1 (standing where the climb ended, facing on along +x):
// the foot of flight 2 is on the landing beside it, facing back along -x (teaching_building
// seed 1, session 24: a foot found there with a diagonal axis and no climb from it).
TEST(PathCentring, FlightFootOfAReturnFlightIsFoundFromItsLanding) {
  const storey::test::World w = u_stair_world();
  map::TraversabilityMap m;
  uint32_t seed = 1;
  for (float x : {-2.0f, -1.0f})  // walking up to flight 1
    for (int r = 0; r < 5; ++r) {
      const Eigen::Vector3f o(x, 0.05f * r - 0.1f, 0.44f);
      m.insert_scan(o, storey::test::scan_vlp16(w, o, 0.1f * r, seed++));
    }
  for (int k : {2, 4, 6, 7})  // climbing it (on tread k)
    for (int r = 0; r < 3; ++r) {
      const Eigen::Vector3f o(0.29f * k + 0.15f, 0.05f * r - 0.05f, 0.168f * (k + 1) + 0.44f);
      m.insert_scan(o, storey::test::scan_vlp16(w, o, 0.1f * r, seed++));
    }
  for (int r = 0; r < 10; ++r) {  // standing on the landing
    const Eigen::Vector3f o(2.93f, 0.04f + 0.01f * r, 1.516f + 0.44f);
    m.insert_scan(o, storey::test::scan_vlp16(w, o, 0.1f * r, seed++));
  }
  m.update_traversability();
  m.update_reachable({2.93f, 0.04f, 1.516f});
  const map::MapView view = m.view();
  const std::vector<Vector3d> near = {{2.93, 0.04, 1.516}, {3.2, 0.5, 1.516}};
  const auto f = flight_foot(view, near, 1.516, 0.45, 1.5, 1.0, /*sparse=*/true);
  ASSERT_TRUE(f.has_value());
  EXPECT_NEAR(f->riser_m.x(), 2.32, 0.1) << f->riser_m.transpose();
  EXPECT_NEAR(f->foot_m.y(), 1.4, 0.15) << f->foot_m.transpose();
  EXPECT_GT(f->foot_m.x(), 2.32 + 0.3) << f->foot_m.transpose();
  EXPECT_NEAR(f->foot_m.z(), 1.516, 0.05);
  EXPECT_NEAR(std::abs(f->yaw_rad), M_PI, 0.15);
  // Without `sparse` the riser is the diagonal line's: a foot off the flight's axis.
  const auto g = flight_foot(view, near, 1.516);
  ASSERT_TRUE(g.has_value());
  EXPECT_GT(std::abs(std::abs(g->yaw_rad) - M_PI), 0.15) << g->yaw_rad;
}
