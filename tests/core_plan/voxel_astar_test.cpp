#include "core/plan/voxel_astar.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "tests/core_plan/voxel_world.hpp"

namespace storey::core::plan {
namespace {

using storey::test::aabb;
using storey::test::World;

// Two rooms (x < 0 and x > 0) split by a wall at x = 0 with a 1.2 m door at y in [1, 2.2].
World two_rooms() {
  World w;
  w.add(aabb({-5, -3, -0.2f}, {5, 3, 0}));
  w.add(aabb({-5, -3.2f, 0}, {5, -3, 2.5f}));
  w.add(aabb({-5, 3, 0}, {5, 3.2f, 2.5f}));
  w.add(aabb({-5.2f, -3, 0}, {-5, 3, 2.5f}));
  w.add(aabb({5, -3, 0}, {5.2f, 3, 2.5f}));
  w.add(aabb({-0.1f, -3, 0}, {0.1f, 1.0f, 2.5f}));
  w.add(aabb({-0.1f, 2.2f, 0}, {0.1f, 3, 2.5f}));
  return w;
}

void expect_path_valid(const map::MapView& view, const VoxelAStar& astar, const VoxelPath& p) {
  ASSERT_EQ(p.status, VoxelAStarStatus::kOk) << to_string(p.status);
  ASSERT_GE(p.points_m.size(), 2u);
  for (size_t i = 1; i < p.points_m.size(); ++i) {
    const Eigen::Vector3d d = p.points_m[i] - p.points_m[i - 1];
    EXPECT_LE(d.head<2>().norm(), view.voxel_size_m() * std::sqrt(2.0) + 1e-6);  // 8-connected
    EXPECT_LE(std::abs(d.z()), view.robot().step_height_m + 1e-6);
    EXPECT_TRUE(astar.passable(view, p.keys[i], float(p.points_m[i].z()))) << i;
  }
}

class VoxelAStarRooms : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    map_ = new map::TraversabilityMap();
    storey::test::scan_world(*map_, two_rooms(),
                             {{-2.5f, 0, 0.5f},
                              {2.5f, 0, 0.5f},
                              {-0.5f, 1.6f, 0.5f},
                              {0.5f, 1.6f, 0.5f},
                              {-2.5f, -2, 0.5f},
                              {2.5f, -2, 0.5f}});
  }
  static void TearDownTestSuite() { delete map_; }
  static map::TraversabilityMap* map_;
};
map::TraversabilityMap* VoxelAStarRooms::map_ = nullptr;

TEST_F(VoxelAStarRooms, GoesThroughTheDoorKeepingClearance) {
  const map::MapView view = map_->view();
  VoxelAStar astar;
  const VoxelPath p = astar.plan(view, {-2.5, 0, 0}, {2.5, 0, 0});
  expect_path_valid(view, astar, p);
  // Through the door: some point crosses x = 0 with y inside the door, with body clearance.
  bool crossed = false;
  for (const auto& q : p.points_m) {
    if (std::abs(q.x()) < 0.15) {
      crossed = true;
      EXPECT_GT(q.y(), 1.0 + 0.2 - 1e-6);
      EXPECT_LT(q.y(), 2.2 - 0.2 + 1e-6);
    }
  }
  EXPECT_TRUE(crossed);
  EXPECT_GT(p.cost, 5.5);  // longer than the 5 m straight line through the wall
  EXPECT_NEAR((p.points_m.back() - Eigen::Vector3d(2.5, 0, 0)).head<2>().norm(), 0, 0.3);
}

TEST_F(VoxelAStarRooms, FailureReasons) {
  const map::MapView view = map_->view();
  VoxelAStar astar;
  EXPECT_EQ(astar.plan(view, {-2.5, 0, 0}, {2.5, 0, 1.5}).status, VoxelAStarStatus::kNoGoalSupport);
  EXPECT_EQ(astar.plan(view, {-2.5, 0, 1.5}, {2.5, 0, 0}).status,
            VoxelAStarStatus::kNoStartSupport);
  EXPECT_EQ(astar.plan(view, {std::nan(""), 0, 0}, {2.5, 0, 0}).status,
            VoxelAStarStatus::kBadInput);
  // Goal against the wall (0.2 m from its face, tolerance 5 cm): its surface exists but the
  // body does not fit there.
  VoxelAStar exact(VoxelAStarOptions{.goal_tolerance_m = 0});
  EXPECT_EQ(exact.plan(view, {-2.5, 0, 0}, {-0.25, -1, 0}).status,
            VoxelAStarStatus::kGoalNotPassable);
  VoxelAStar bounded(VoxelAStarOptions{.max_expansions = 50});
  const VoxelPath b = bounded.plan(view, {-2.5, 0, 0}, {2.5, 0, 0});
  EXPECT_EQ(b.status, VoxelAStarStatus::kExpansionLimit);
  EXPECT_EQ(b.expansions, 50u);
  EXPECT_STREQ(to_string(b.status), "expansion limit reached before the goal");
}

TEST(VoxelAStar, ClosedDoorMeansNoPath) {
  World w = two_rooms();
  w.add(aabb({-0.1f, 1.0f, 0}, {0.1f, 2.2f, 2.5f}));  // door shut
  map::TraversabilityMap m;
  storey::test::scan_world(m, w, {{-2.5f, 0, 0.5f}, {2.5f, 0, 0.5f}});
  VoxelAStar astar(VoxelAStarOptions{.reachable_only = false});
  const VoxelPath p = astar.plan(m.view(), {-2.5, 0, 0}, {2.5, 0, 0});
  EXPECT_EQ(p.status, VoxelAStarStatus::kNoPath) << to_string(p.status);
  EXPECT_GT(p.expansions, 100u);
}

TEST(VoxelAStar, ClimbsStairs) {
  // Floor, 6 steps (0.15 m rise, 0.30 m tread) along +x from x = 1, a landing at 0.9 m.
  World w;
  w.add(aabb({-3, -1.5f, -0.2f}, {1, 1.5f, 0}));
  w.stairs(1, -0.8f, 0.8f, 0, 6, 0.15f, 0.30f);
  w.add(aabb({2.8f, -1.5f, -0.2f}, {6, 1.5f, 0.9f}));
  w.add(aabb({-3, -1.7f, 0}, {6, -1.5f, 3.0f}));
  w.add(aabb({-3, 1.5f, 0}, {6, 1.7f, 3.0f}));
  map::TraversabilityMap m;
  storey::test::scan_world(
      m, w, {{-1, 0, 0.5f}, {0.5f, 0, 0.5f}, {1.9f, 0, 0.95f}, {4, 0, 1.4f}, {3, 0, 1.4f}});
  const map::MapView view = m.view();
  VoxelAStar astar(VoxelAStarOptions{.reachable_only = false});
  const VoxelPath p = astar.plan(view, {-1, 0, 0}, {4, 0, 0.9});
  expect_path_valid(view, astar, p);
  EXPECT_NEAR(p.points_m.front().z(), 0.0, 0.06);
  EXPECT_NEAR(p.points_m.back().z(), 0.9, 0.06);
  // The climb happens on the stairs, never as a jump at the landing edge.
  for (size_t i = 1; i < p.points_m.size(); ++i)
    EXPECT_LE(p.points_m[i].z() - p.points_m[i - 1].z(), 0.18 + 1e-6);
}

}  // namespace
}  // namespace storey::core::plan
