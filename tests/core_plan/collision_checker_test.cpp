#include "core/plan/collision_checker.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "tests/core_plan/voxel_world.hpp"

namespace storey::core::plan {
namespace {

using storey::test::fill_voxels;

std::vector<BodyPose> line_poses(Eigen::Vector3d a, Eigen::Vector3d b, double spacing, double yaw,
                                 double pitch = 0) {
  std::vector<BodyPose> p;
  const int n = int(std::ceil((b - a).norm() / spacing));
  for (int i = 0; i <= n; ++i) p.push_back({a + (b - a) * (double(i) / n), yaw, pitch, double(i)});
  return p;
}

TEST(CollisionChecker, SpacingIsHalfTheSmallestBoxDimension) {
  RobotModel robot;
  CollisionChecker cc(robot, 0.1);
  EXPECT_NEAR(cc.box_size_m().x(), 0.80, 1e-12);
  EXPECT_NEAR(cc.box_size_m().y(), 0.41, 1e-12);
  EXPECT_NEAR(cc.box_size_m().z(), 0.45, 1e-12);
  EXPECT_NEAR(cc.max_sample_spacing_m(), 0.205, 1e-12);
  EXPECT_LE(cc.max_dt_s() * robot.max_speed_mps, cc.max_sample_spacing_m() + 1e-12);
}

TEST(CollisionChecker, BoxInTheWayCollidesFloorDoesNot) {
  CollisionChecker cc(RobotModel{}, 0.1);
  std::vector<Eigen::Vector3f> vox;
  fill_voxels(vox, {-2, -1, -0.1f}, {5, 1, 0});  // floor, surface at z = 0
  const auto poses = line_poses({0, 0, 0}, {4, 0, 0}, 0.2, 0.0);
  CollisionHit h = cc.check_poses(poses, vox);
  EXPECT_FALSE(h.collides);
  EXPECT_EQ(h.poses_checked, poses.size());
  EXPECT_EQ(h.voxels_loaded, 0u);  // the floor is ground for every pose: not even loaded
  fill_voxels(vox, {2.0f, -0.3f, 0}, {2.3f, 0.3f, 0.5f});  // a 0.3 m block on the path
  h = cc.check_poses(poses, vox);
  ASSERT_TRUE(h.collides);
  // Body front (0.35 + margin 0.05 ahead of the foot point) reaches the block face (x = 2.0,
  // first voxel centre 2.05 - 0.05 extent) between x = 1.6 and 1.65.
  EXPECT_NEAR(poses[h.sample].foot_m.x(), 1.6, 0.2 + 1e-9);
  EXPECT_GE(h.voxel_m.x(), 2.0);
  // A low obstacle (below step height) is stepped over: ground.
  std::vector<Eigen::Vector3f> curb;
  fill_voxels(curb, {-2, -1, -0.1f}, {5, 1, 0});
  fill_voxels(curb, {2.0f, -1, 0}, {2.2f, 1, 0.15f});
  EXPECT_FALSE(cc.check_poses(poses, curb).collides);
}

TEST(CollisionChecker, ClearCorridorDoesNotCollideNarrowOneDoes) {
  CollisionChecker cc(RobotModel{}, 0.1);
  for (double half_gap : {0.35, 0.15}) {
    std::vector<Eigen::Vector3f> vox;
    fill_voxels(vox, {-1, -2, -0.1f}, {6, 2, 0});
    fill_voxels(vox, {-1, float(half_gap), 0}, {6, float(half_gap) + 0.2f, 1.0f});
    fill_voxels(vox, {-1, -float(half_gap) - 0.2f, 0}, {6, -float(half_gap), 1.0f});
    const auto poses = line_poses({0, 0, 0}, {5, 0, 0}, 0.2, 0.0);
    EXPECT_EQ(cc.check_poses(poses, vox).collides, half_gap < 0.2) << half_gap;
    // Turning across the corridor (yaw 90 deg) makes the 0.8 m long box hit even the wide one.
    const auto sideways = line_poses({0, 0, 0}, {5, 0, 0}, 0.2, M_PI / 2);
    EXPECT_TRUE(cc.check_poses(sideways, vox).collides) << half_gap;
  }
}

TEST(CollisionChecker, StairsUnderTheFeetAreNotCollisions) {
  // 8 steps of 0.15 m rise, 0.30 m tread, solid, rising along +x from x = 0.
  CollisionChecker cc(RobotModel{}, 0.1);
  std::vector<Eigen::Vector3f> vox;
  fill_voxels(vox, {-2, -1, -0.1f}, {0, 1, 0});
  for (int i = 0; i < 8; ++i)
    fill_voxels(vox, {0.3f * i, -1, -0.1f}, {0.3f * (i + 1), 1, 0.15f * (i + 1)});
  fill_voxels(vox, {2.4f, -1, -0.1f}, {5, 1, 1.2f});  // landing
  // Climbing along the flight's mid line (nosing-to-tread average), pitched with the slope.
  const double pitch = std::atan2(0.15, 0.30);
  std::vector<BodyPose> poses;
  for (double x = 0.3; x <= 2.1; x += 0.1)
    poses.push_back({{x, 0, 0.5 * x + 0.075}, 0.0, pitch, x});
  CollisionHit h = cc.check_poses(poses, vox);
  EXPECT_FALSE(h.collides) << "sample " << h.sample << " voxel " << h.voxel_m.transpose();
  // The same flight taken level (no pitch) puts the upper treads into the body box.
  for (auto& p : poses) p.pitch_rad = 0;
  EXPECT_TRUE(cc.check_poses(poses, vox).collides);
  // Stairs with a low beam overhead collide.
  for (auto& p : poses) p.pitch_rad = pitch;
  fill_voxels(vox, {1.0f, -1, 1.0f}, {1.2f, 1, 1.1f});
  EXPECT_TRUE(cc.check_poses(poses, vox).collides);
}

TEST(CollisionChecker, TerrainPitchNeedsSupportUnderBothEnds) {
  // A tread seen ahead of the body, nothing seen behind it (the top of a flight climbed blind:
  // the robot's foot lies on the line over the nosings, above the last tread seen).
  storey::test::World w;
  w.add(storey::test::aabb({0.2f, -1, 2.5f}, {1.0f, 1, 2.66f}));
  map::TraversabilityMap m;
  storey::test::scan_world(m, w, {{2.5f, 0, 4.0f}});
  CollisionChecker cc(RobotModel{}, m.view().voxel_size_m());
  const BodyPose p{{0.25, 0, 2.81}, 0.0, 0.3};
  ASSERT_TRUE(m.view().support_surface_near({0.6f, 0, 2.81f}, 0.5).has_value());  // front seen
  // One end unseen, the seen one below the foot: no terrain pitch (the pose's own stands);
  // taking the unseen end at the foot's height would pitch the body nose down (-12 deg).
  EXPECT_FALSE(cc.terrain_pitch(m.view(), p).has_value());
  // The seen end above the foot (front legs on a tread, rear ones on ground unseen): the
  // unseen end at the foot's height.
  const BodyPose low{{0.25, 0, 2.5}, 0.0, 0.0};
  const auto up = cc.terrain_pitch(m.view(), low);
  ASSERT_TRUE(up.has_value());
  EXPECT_NEAR(*up, std::atan2(0.16, 0.7), 0.05);
  // Seen under both ends: the slope between them.
  w.add(storey::test::aabb({-0.8f, -1, 2.3f}, {0.0f, 1, 2.46f}));
  storey::test::scan_world(m, w, {{-2.5f, 0, 4.0f}});
  const auto tp = cc.terrain_pitch(m.view(), p);
  ASSERT_TRUE(tp.has_value());
  EXPECT_GT(*tp, 0.1);
}

// A walk from a flight's top tread onto its landing over the unseen tread between: the path rises
// 0.33 m in 0.3 m and the pose's pitch (48 deg) would put the body's rear into the tread it
// stands on. With the end ahead unseen and the one behind seen below the foot, the pitch is
// bounded so that the rear stands no lower than that tread (office seed 1, session 25).
TEST(CollisionChecker, TerrainPitchKeepsTheSeenEndOnItsSupport) {
  storey::test::World w;
  w.add(storey::test::aabb({-1.0f, -1, 2.5f}, {0.0f, 1, 2.67f}));  // the tread behind
  map::TraversabilityMap m;
  storey::test::scan_world(m, w, {{-2.5f, 0, 4.0f}});
  CollisionChecker cc(RobotModel{}, m.view().voxel_size_m());
  const BodyPose p{{0.05, 0, 2.75}, 0.0, std::atan2(0.33, 0.3)};
  ASSERT_FALSE(m.view().support_surface_near({0.4f, 0, 2.75f}, 0.5).has_value());  // ahead unseen
  const auto tp = cc.terrain_pitch(m.view(), p);
  ASSERT_TRUE(tp.has_value());
  const double half = 0.5 * RobotModel{}.body_length_m;
  EXPECT_NEAR(*tp, std::atan2(2.75 - 2.67, half), 0.03);
  const std::vector<BodyPose> poses{p};
  EXPECT_FALSE(cc.check_poses(m.view(), poses).collides);
  // A pose pitched less than that bound keeps its own pitch.
  const BodyPose gentle{{0.05, 0, 2.75}, 0.0, 0.1};
  EXPECT_FALSE(cc.terrain_pitch(m.view(), gentle).has_value());
}

// At a flight's foot the straight walk's first pose is pitched with its first chord (27 deg
// up the line to the landing) while the body still stands on the level floor. Where the map says
// level under both ends the box is levelled too (within the floor-noise bound): else its rear
// dips into the floor behind and every climb from the foot collides at its first pose (teaching
// building seeds 4 and 5, session 39).
TEST(CollisionChecker, APitchedPoseOnAMappedLevelFloorStandsLevel) {
  storey::test::World w;
  w.add(storey::test::aabb({-3.0f, -1.5f, -0.2f}, {3.0f, 1.5f, 0.0f}));  // the floor
  for (int i = 0; i < 4; ++i)  // the flight's first risers, 0.65 m ahead of the foot
    w.add(storey::test::aabb({0.65f + 0.3f * i, -0.6f, 0.0f},
                             {0.65f + 0.3f * (i + 1), 0.6f, 0.17f * (i + 1)}));
  map::TraversabilityMap m;
  storey::test::scan_world(m, w, {{-2.0f, 0, 1.0f}, {-1.0f, 1.2f, 1.0f}, {-1.0f, -1.2f, 1.0f}});
  CollisionChecker cc(RobotModel{}, m.view().voxel_size_m());
  // The foot's height a few cm under the floor's mapped points (odometry against map noise).
  const BodyPose foot{{0.0, 0, -0.02}, 0.0, 0.467};
  const auto tp = cc.terrain_pitch(m.view(), foot);
  ASSERT_TRUE(tp.has_value());    // both ends seen ...
  EXPECT_LT(std::abs(*tp), 0.1);  // ... and level
  for (const BodyPose& p :
       {foot, BodyPose{{0.0, 0, 0.0}, 0.0, 0.6}, BodyPose{{0.0, 0, -0.02}, 0.0, -0.467}}) {
    const std::vector<BodyPose> poses{p};
    const CollisionHit h = cc.check_poses(m.view(), poses);
    EXPECT_FALSE(h.collides) << "pitch " << p.pitch_rad << " voxel " << h.voxel_m.transpose();
  }
  // A real obstacle in the body's way still collides with the box levelled.
  w.add(storey::test::aabb({-0.3f, -0.2f, 0.2f}, {-0.1f, 0.2f, 0.35f}));
  storey::test::scan_world(m, w, {{-2.0f, 0, 1.0f}});
  EXPECT_TRUE(cc.check_poses(m.view(), std::vector<BodyPose>{foot}).collides);
}

TEST(CollisionChecker, NonFinitePoseIsReportedNotSafe) {
  CollisionChecker cc(RobotModel{}, 0.1);
  std::vector<Eigen::Vector3f> vox;
  std::vector<BodyPose> poses{{{0, 0, 0}, 0}, {{std::nan(""), 0, 0}, 0}};
  const CollisionHit h = cc.check_poses(poses, vox);
  EXPECT_TRUE(h.collides);
  EXPECT_TRUE(h.bad_input);
  EXPECT_EQ(h.sample, 1u);
}

TEST(CollisionChecker, MapViewLookAheadAndSegments) {
  // A room scanned by the synthetic LiDAR: floor, walls, and a pillar in the middle.
  storey::test::World w;
  w.add(storey::test::aabb({-4, -3, -0.2f}, {6, 3, 0}));
  w.add(storey::test::aabb({-4, -3.2f, 0}, {6, -3, 2.5f}));
  w.add(storey::test::aabb({-4, 3, 0}, {6, 3.2f, 2.5f}));
  w.add(storey::test::aabb({2.0f, -0.3f, 0}, {2.4f, 0.3f, 2.5f}));  // pillar
  map::TraversabilityMap m;
  storey::test::scan_world(m, w, {{0, 0, 0.5f}, {0, 1.5f, 0.5f}});
  const map::MapView view = m.view();
  CollisionChecker cc(RobotModel{}, view.voxel_size_m());
  // Straight into the pillar at 1 m/s: hit within the 2 s look-ahead, after ~1.6 s.
  auto straight = [](double t) { return BodyPose{{t, 0, 0.0}, 0.0}; };
  const CollisionHit h = cc.check_ahead(view, straight, 0.0, 2.0, 0.02);
  ASSERT_TRUE(h.collides);
  EXPECT_NEAR(h.t_s, 1.6, 0.1);
  EXPECT_FALSE(cc.check_ahead(view, straight, 0.0, 1.0, 0.02).collides);  // 1 s: still clear
  // Passing the pillar with 1 m of clearance does not collide.
  auto offset = [](double t) { return BodyPose{{t, 1.5, 0.0}, 0.0}; };
  EXPECT_FALSE(cc.check_ahead(view, offset, 0.0, 3.5, 0.02).collides);
  EXPECT_TRUE(cc.check_segment(view, {0, 0, 0}, {3, 0, 0}, std::nan("")).collides);
  EXPECT_FALSE(cc.check_segment(view, {0, 1.2, 0}, {3.5, 1.2, 0}, std::nan("")).collides);
}

TEST(CollisionChecker, LookAheadOnTheGridChecksOnlyPlanTimePoses) {
  // The plan-time check of a trajectory over [t0, t1] and a look-ahead started anywhere along
  // it: the look-ahead's poses are plan-time poses, and they cover its window.
  map::TraversabilityMap m;
  const map::MapView view = m.view();
  CollisionChecker cc(RobotModel{}, view.voxel_size_m());
  const double t0 = 3.7, t1 = 9.15;
  std::vector<double> plan_t, ahead_t;
  auto record = [](std::vector<double>& into) {
    return [&into](double t) {
      into.push_back(t);
      return BodyPose{{t, 0, 0}, 0.0};
    };
  };
  cc.check_ahead(view, record(plan_t), t0, t1 - t0, 0.0);
  ASSERT_GT(plan_t.size(), 10u);
  for (double from : {t0, 4.0, 5.123, 8.9, t1}) {
    ahead_t.clear();
    cc.check_on_grid(view, record(ahead_t), t0, t1, from, 2.0);
    ASSERT_FALSE(ahead_t.empty());
    for (double t : ahead_t) {
      bool on_grid = false;
      for (double p : plan_t) on_grid = on_grid || std::abs(p - t) < 1e-9;
      EXPECT_TRUE(on_grid) << "look-ahead from " << from << " sampled t = " << t;
    }
    EXPECT_LE(ahead_t.front(), from + 1e-9);
    EXPECT_GE(ahead_t.back(), std::min(t1, from + 2.0) - 1e-9);
    EXPECT_LE(ahead_t.back() - ahead_t.front(), 2.0 + 2 * cc.max_dt_s() + 1e-9);
  }
  // The plain look-ahead started half a sample off the grid samples other poses.
  ahead_t.clear();
  cc.check_ahead(view, record(ahead_t), t0 + 0.5 * cc.max_dt_s(), 1.0, 0.0);
  EXPECT_GT(std::abs(ahead_t.front() - plan_t.front()), 1e-6);
}

}  // namespace
}  // namespace storey::core::plan
