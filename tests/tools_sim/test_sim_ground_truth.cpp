// Ground truth horizontal clearance: the truth mirrors the map's R_col (paper III-A Eq. 3,
// map.collision_radius_m), so support voxels no robot could stand on next to walls do not count.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "tools/sim/ground_truth.hpp"
#include "tools/sim/scene.hpp"

namespace sim = storey::tools::sim;

namespace {
sim::GroundTruthOptions with_radius(double r) {
  sim::GroundTruthOptions o;
  o.collision_radius = r;
  return o;
}
}  // namespace

TEST(SimGroundTruthClearance, DefaultMirrorsTheMapsCollisionRadius) {
  EXPECT_DOUBLE_EQ(sim::GroundTruthOptions{}.collision_radius, 0.1);
}

// test_box_room: inner wall faces at x = 0.4 and 5.6. A face on a voxel boundary belongs to the
// voxel above it, so the wall voxels are x = 4 and x = 56; floor support spans x = 5..55.
TEST(SimGroundTruthClearance, VoxelNextToAWallIsNotTruthOneAtTwoVoxelsIs) {
  const sim::Scene s = sim::load_scene("test_box_room");
  const sim::GroundTruth gt(s.mesh, s.start);
  const int y = 20;  // y = 2.0 m, the middle of the room
  for (const int wall : {4, 56}) {
    const int in = wall == 4 ? 1 : -1;  // towards the room
    SCOPED_TRACE(wall);
    EXPECT_TRUE(gt.occupied({wall, y, 5}));  // the wall itself, 0.5 m up
    const sim::VoxelKey next{wall + in, y, 0}, two{wall + 2 * in, y, 0};
    EXPECT_TRUE(gt.support(next));  // free above: support...
    EXPECT_FALSE(gt.clear(next));   // ...but within R_col of the wall
    EXPECT_FALSE(gt.reachable(next));
    EXPECT_TRUE(gt.clear(two));  // 0.2 m from the wall voxel: clear
    EXPECT_TRUE(gt.reachable(two));
  }
  // Radius 0 keeps the old definition: the voxel next to the wall counts.
  const sim::GroundTruth gt0(s.mesh, s.start, with_radius(0.0));
  EXPECT_TRUE(gt0.reachable({5, y, 0}));
  EXPECT_TRUE(gt0.reachable({55, y, 0}));
}

// The ring of voxels within R_col of the four walls leaves the truth: 51 x 31 support voxels
// without clearance, 49 x 29 with R_col = 1 voxel (disc dx^2 + dy^2 <= 1: corners lose one ring
// too), so the ring is 2 * 51 + 2 * 31 - 4 = 160 voxels = 1.6 m^2 = 0.16 m^3.
TEST(SimGroundTruthClearance, BoxRoomTruthShrinksByTheWallRing) {
  const sim::Scene s = sim::load_scene("test_box_room");
  const sim::GroundTruth gt0(s.mesh, s.start, with_radius(0.0));
  const sim::GroundTruth gt(s.mesh, s.start);
  ASSERT_EQ(gt0.reachable_voxels().size(), 51u * 31u);
  EXPECT_EQ(gt.reachable_voxels().size(), 49u * 29u);
  EXPECT_NEAR(gt0.traversable_volume_m3() - gt.traversable_volume_m3(), 0.160, 1e-9);
  ASSERT_EQ(gt.floors().size(), 1u);
  EXPECT_NEAR(gt0.floors()[0].traversable_area_m2 - gt.floors()[0].traversable_area_m2, 1.60, 1e-9);
  // A wider radius removes a wider ring: ceil(0.2 / 0.1) = 2 voxels, 47 x 27.
  const sim::GroundTruth gt2(s.mesh, s.start, with_radius(0.2));
  EXPECT_EQ(gt2.reachable_voxels().size(), 47u * 27u);
}

// test_stair: 1.2 m wide flight centred on y = 1.2 between 0.12 m side walls (inner faces
// y = 0.6, 1.8 -> wall voxels y = 6 and 18), 17 treads 0.29 m deep, rise 3.0 / 18 m. The next
// tread up (0.167 m) is below the step height, so it is no obstacle: every tread keeps its middle
// and the flood fill from floor 0 reaches floor 1.
TEST(SimGroundTruthClearance, StairsStayConnectedFromFloor0ToFloor1) {
  const sim::Scene s = sim::load_scene("test_stair");
  const sim::GroundTruth gt0(s.mesh, s.start, with_radius(0.0));
  const sim::GroundTruth gt(s.mesh, s.start);
  ASSERT_EQ(gt.floors().size(), 2u);
  EXPECT_NEAR(gt.floors()[1].z_m, 3.0, 1e-9);
  EXPECT_GT(gt.floors()[1].traversable_area_m2, 15.0);  // reached only over the stairs
  for (int k = 0; k < 17; ++k) {
    SCOPED_TRACE(k);
    const double x = 1.8 + k * 0.29 + 0.145, z = (k + 1) * 3.0 / 18;
    const sim::VoxelKey mid = sim::voxel_key({x, 1.2, z}, 0.1);
    EXPECT_TRUE(gt.reachable(mid));
    // Across the width: the voxels next to the side walls go, the 0.9 m between them stay.
    int across = 0;
    for (int y = 7; y <= 17; ++y) across += gt.reachable({mid.x, y, mid.z}) ? 1 : 0;
    EXPECT_EQ(across, 9);
    EXPECT_FALSE(gt.reachable({mid.x, 7, mid.z}));
    EXPECT_FALSE(gt.reachable({mid.x, 17, mid.z}));
    EXPECT_TRUE(gt0.reachable({mid.x, 7, mid.z}));
  }
  // Along the centre line every column of the flight is truth (the voxels at each riser too).
  for (double x = 1.85; x < 1.8 + 17 * 0.29; x += 0.1) {
    const sim::VoxelKey c = sim::voxel_key({x, 1.2, 0.0}, 0.1);
    bool any = false;
    for (int z = 0; z <= 31 && !any; ++z) any = gt.reachable({c.x, c.y, z});
    EXPECT_TRUE(any) << "x " << x;
  }
}

TEST(SimGroundTruthClearance, RampStaysConnected) {
  const sim::Scene s = sim::load_scene("test_ramp");
  const sim::GroundTruth gt(s.mesh, s.start);
  ASSERT_EQ(gt.floors().size(), 2u);
  EXPECT_GT(gt.floors()[1].traversable_area_m2, 60.0);
}

TEST(SimGroundTruthClearance, BadRadiusIsRefusedByName) {
  const sim::Scene s = sim::load_scene("test_box_room");
  for (const double r : {-0.1, 5.0, std::numeric_limits<double>::quiet_NaN()}) {
    try {
      const sim::GroundTruth gt(s.mesh, s.start, with_radius(r));
      ADD_FAILURE() << r;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find("collision_radius"), std::string::npos) << e.what();
    }
  }
}

// A start pose right against a wall seeds the truth from the nearest voxel with clearance
// (the map seeds C_reach within map.seed_search_radius_m likewise).
TEST(SimGroundTruthClearance, StartAgainstAWallSeedsFromNearestClearVoxel) {
  const sim::Scene s = sim::load_scene("test_box_room");
  const sim::GroundTruth gt(s.mesh, sim::StartPose{5.55, 2.05, 0.0, 0.0});
  EXPECT_EQ(gt.start_voxel().x, 54);
  EXPECT_TRUE(gt.reachable(gt.start_voxel()));
  EXPECT_EQ(gt.reachable_voxels().size(), 49u * 29u);
}
