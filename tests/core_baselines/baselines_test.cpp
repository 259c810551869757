// The baselines of core/baselines/ on synthetic LiDAR worlds: behaviour that tells them apart.
#include <gtest/gtest.h>

#include "core/baselines/fael_like_planner.hpp"
#include "core/baselines/nearest_frontier_planner.hpp"
#include "core/baselines/tare_like_planner.hpp"
#include "core/map/traversability_map.hpp"
#include "tests/core_map/synthetic_world.hpp"

namespace storey::core::baselines {
namespace {

using storey::test::aabb;
using storey::test::World;

// Scans w from each origin with a short range (the map ends where the range does), then
// traversability and C_reach from the first origin's foot point.
void scan(map::TraversabilityMap& m, const World& w, const std::vector<Eigen::Vector3f>& origins,
          float range) {
  uint32_t seed = 1;
  for (const Eigen::Vector3f& o : origins)
    for (int rep = 0; rep < 3; ++rep)
      m.insert_scan(o, storey::test::scan_dense(w, o, 60000, seed++, -1.4f, 0.9f, range, 0.002f));
  m.update_traversability();
  m.update_reachable(origins.front() - Eigen::Vector3f(0, 0, 0.5f));
}

// A 3 m wide corridor along x, from -half_length to +half_length, walls 2.5 m high.
World corridor_along_x(float half_length) {
  World w;
  w.add(aabb({-half_length, -1.5f, -0.2f}, {half_length, 1.5f, 0}));
  w.add(aabb({-half_length, -1.7f, 0}, {half_length, -1.5f, 2.5f}));
  w.add(aabb({-half_length, 1.5f, 0}, {half_length, 1.7f, 2.5f}));
  return w;
}

plan::ExplorationInput input_at(const map::MapView& view, const Eigen::Vector3d& foot) {
  plan::ExplorationInput in;
  in.view = &view;
  in.robot_foot_m = foot;
  in.t_s = 1.0;
  return in;
}

TEST(TareLink, RefusesAStepButAcceptsAGentleRamp) {
  const Eigen::Vector3d a(0, 0, 0);
  // 0.5 m up over 1 m (a stair flight's rise): refused.
  EXPECT_FALSE(tare_link_ok(a, {1, 0, 0.5}, 0.3, 1.0));
  // A 5 deg ramp rises 0.087 m over 1 m: linked.
  const double up = std::tan(5.0 * M_PI / 180.0);
  EXPECT_TRUE(tare_link_ok(a, {1, 0, up}, 0.3, 1.0));
  EXPECT_TRUE(tare_link_ok(a, {0, 1, -up}, 0.3, 1.0));
  // A short link on a stair (one tread: 0.28 m run, 0.17 m rise) is refused like a long one.
  EXPECT_FALSE(tare_link_ok(a, {0.28, 0, 0.17}, 0.3, 1.0));
  // Paths: a 5 deg ramp profile passes, a stair profile does not.
  std::vector<Eigen::Vector3d> ramp, stair;
  for (int i = 0; i <= 40; ++i) {
    const double x = 0.1 * i;
    ramp.push_back({x, 0, x * up});
    stair.push_back({x, 0, 0.17 * std::floor(x / 0.28)});
  }
  EXPECT_TRUE(tare_path_ok(ramp, 0.3, 1.0));
  EXPECT_FALSE(tare_path_ok(stair, 0.3, 1.0));
}

// Corridor along x (walls at y = +-1.5), scanned with a 4 m range from x = 0 and x = 2: known
// floor from about x = -4 to x = 6, unknown beyond; C_reach (well-observed ground) ends at
// about x = -2 and x = 3.7, where the frontiers are. From x = 0 the -x one is nearer, from x = 2
// the +x one.
TEST(NearestFrontier, PicksTheNearerOfTwoFrontiers) {
  const World w = corridor_along_x(12);
  map::TraversabilityMap m;
  scan(m, w, {{0, 0, 0.5f}, {2, 0, 0.5f}}, 4.0f);
  const map::MapView view = m.view();
  const auto clusters = volumetric_frontiers(view, 4);
  bool minus = false, plus = false;
  for (const auto& c : clusters) {
    minus = minus || c.centroid_m.x() < -1.0;
    plus = plus || c.centroid_m.x() > 3.0;
  }
  std::string where;
  for (const auto& c : clusters)
    where += " (" + std::to_string(c.centroid_m.x()) + ", " + std::to_string(c.centroid_m.y()) +
             ": " + std::to_string(c.voxels.size()) + ")";
  ASSERT_TRUE(minus && plus) << clusters.size() << " clusters:" << where;
  NearestFrontierPlanner p(RobotModel{}, plan::PlanOptions{}, 0.1);
  const plan::ExplorationResult r = p.plan(input_at(view, {0, 0, 0}));
  ASSERT_EQ(r.status, plan::ExplorationStatus::kNewTrajectory) << r.reason;
  EXPECT_LT(r.target_m.x(), -1.0);
  // Mirrored start (robot at x = 2): the +x frontier is now the nearer one.
  NearestFrontierPlanner q(RobotModel{}, plan::PlanOptions{}, 0.1);
  const plan::ExplorationResult s = q.plan(input_at(view, {2, 0, 0}));
  ASSERT_EQ(s.status, plan::ExplorationStatus::kNewTrajectory) << s.reason;
  EXPECT_GT(s.target_m.x(), 3.0);
}

// Floor with stairs rising along +x from x = 1 (6 steps, 0.17 m rise, 0.28 m tread) to a
// landing: on the start floor's 2D grid the treads are obstacles, the floor is free, and no
// fael-like goal lies above the floor's band.
TEST(FaelLike, TreatsAStairAsAnObstacle) {
  World w;
  w.add(aabb({-3, -1.5f, -0.2f}, {1, 1.5f, 0}));
  w.stairs(1, -0.8f, 0.8f, 0, 6, 0.17f, 0.28f);
  w.add(aabb({2.68f, -1.5f, -0.2f}, {6, 1.5f, 1.02f}));
  w.add(aabb({-3, -1.7f, 0}, {6, -1.5f, 3.0f}));
  w.add(aabb({-3, 1.5f, 0}, {6, 1.7f, 3.0f}));
  map::TraversabilityMap m;
  scan(m, w, {{-1, 0, 0.5f}, {0.5f, 0, 0.5f}, {1.9f, 0, 1.0f}}, 8.0f);
  const map::MapView view = m.view();
  TraversabilityGrid2D grid;
  grid.build(view, 0.0, 0.15, 0.1, 0.45);
  EXPECT_EQ(grid.at_m(-1.0, 0.0), GridCell::kFree);
  EXPECT_EQ(grid.at_m(0.5, 0.3), GridCell::kFree);
  for (double x : {1.42, 1.70, 1.98, 2.26})  // tread centres of steps 2..5
    EXPECT_EQ(grid.at_m(x, 0.0), GridCell::kObstacle) << "x = " << x;
  // The landing (1.02 m up) is not on the plane: an obstacle, never free.
  EXPECT_NE(grid.at_m(4.0, 0.0), GridCell::kFree);

  FaelLikePlanner p(RobotModel{}, plan::PlanOptions{}, 0.1);
  const auto goals = p.goals(input_at(view, {-1, 0, 0}));
  for (const Goal& g : goals) {
    EXPECT_LT(g.p_m.z(), 0.15);
    for (const Eigen::Vector3d& q : g.path_m) EXPECT_LT(q.z(), 0.15);
  }
}

// The same stairs for tare-like's path rule, against the voxel A*: a path up the flight is
// refused, one along the floor is accepted.
TEST(TareLike, RefusesThePathUpAStairFlight) {
  World w;
  w.add(aabb({-3, -1.5f, -0.2f}, {1, 1.5f, 0}));
  w.stairs(1, -0.8f, 0.8f, 0, 6, 0.17f, 0.28f);
  w.add(aabb({2.68f, -1.5f, -0.2f}, {6, 1.5f, 1.02f}));
  w.add(aabb({-3, -1.7f, 0}, {6, -1.5f, 3.0f}));
  w.add(aabb({-3, 1.5f, 0}, {6, 1.7f, 3.0f}));
  map::TraversabilityMap m;
  scan(m, w, {{-1, 0, 0.5f}, {0.5f, 0, 0.5f}, {1.9f, 0, 1.0f}, {4, 0, 1.52f}}, 8.0f);
  const map::MapView view = m.view();
  plan::VoxelAStar astar(plan::VoxelAStarOptions{.reachable_only = false});
  const plan::VoxelPath up = astar.plan(view, {-1, 0, 0}, {4, 0, 1.02});
  ASSERT_EQ(up.status, plan::VoxelAStarStatus::kOk);
  EXPECT_FALSE(tare_path_ok(up.points_m, 0.3, 1.0));
  const plan::VoxelPath flat = astar.plan(view, {-1, 0, 0}, {0.5, 0.8, 0});
  ASSERT_EQ(flat.status, plan::VoxelAStarStatus::kOk);
  EXPECT_TRUE(tare_path_ok(flat.points_m, 0.3, 1.0));
}

// GoalDriver's fallback path (tare-like: its own viewpoint graph) is taken only where the voxel
// A* finds no path, and the trajectory then follows it.
TEST(GoalDriver, FallbackPathOnlyWhereTheVoxelAStarFails) {
  const World w = corridor_along_x(6);
  map::TraversabilityMap m;
  scan(m, w, {{0, 0, 0.5f}, {3, 0, 0.5f}}, 6.0f);
  const map::MapView view = m.view();
  const plan::ExplorationInput in = input_at(view, {0, 0, 0});
  GoalDriver d(RobotModel{}, plan::PlanOptions{}, 0.1, BaselineOptions{});
  int calls = 0;
  d.set_fallback_path([&](const plan::ExplorationInput& i, const Goal&) {
    ++calls;
    return std::vector<Eigen::Vector3d>{i.robot_foot_m, {1.5, 0, 0}, {3, 0, 0}};
  });
  Goal on_floor;
  on_floor.p_m = {3, 0, 0};
  plan::ExplorationResult r;
  ASSERT_TRUE(d.drive(in, on_floor, r)) << r.reason;
  EXPECT_EQ(calls, 0);  // the voxel A* found it
  Goal in_the_air;      // no support under it: the voxel A* fails
  in_the_air.p_m = {3, 0, 1.5};
  plan::ExplorationResult f;
  ASSERT_TRUE(d.drive(in, in_the_air, f));
  EXPECT_EQ(calls, 1);
  EXPECT_LT((f.trajectory.sample(f.trajectory.t_end()).p_m - Eigen::Vector3d(3, 0, 0)).norm(), 0.2);
  GoalDriver plain(RobotModel{}, plan::PlanOptions{}, 0.1, BaselineOptions{});
  plan::ExplorationResult n;
  EXPECT_FALSE(plain.drive(in, in_the_air, n));
}

TEST(Baselines, BadInputFails) {
  plan::ExplorationInput in;
  NearestFrontierPlanner a(RobotModel{}, plan::PlanOptions{}, 0.1);
  FaelLikePlanner b(RobotModel{}, plan::PlanOptions{}, 0.1);
  TareLikePlanner c(RobotModel{}, plan::PlanOptions{}, 0.1);
  EXPECT_EQ(a.plan(in).status, plan::ExplorationStatus::kFailed);
  EXPECT_EQ(b.plan(in).status, plan::ExplorationStatus::kFailed);
  EXPECT_EQ(c.plan(in).status, plan::ExplorationStatus::kFailed);
}

}  // namespace
}  // namespace storey::core::baselines
