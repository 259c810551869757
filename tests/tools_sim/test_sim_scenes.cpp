// Scenes, mesh I/O and ground truth of the world simulator (tools/sim).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>

#include "tools/sim/ground_truth.hpp"
#include "tools/sim/mesh_io.hpp"
#include "tools/sim/metrics.hpp"
#include "tools/sim/render.hpp"
#include "tools/sim/scene.hpp"

namespace sim = storey::tools::sim;

namespace {
std::string tmp_path(const std::string& name) {
  return (std::filesystem::temp_directory_path() / ("storey_test_sim_" + name)).string();
}
}  // namespace

TEST(SimScenes, ObjExportRoundTripsThroughAssimp) {
  const sim::Scene s = sim::load_scene("house");
  const std::string p = tmp_path("house.obj");
  sim::export_obj(s.mesh, p);
  const sim::Mesh m = sim::load_mesh(p);
  EXPECT_EQ(m.size(), s.mesh.size());
  EXPECT_NEAR(m.area(), s.mesh.area(), 1e-3 * s.mesh.area());
  const auto a = s.mesh.bounds(), b = m.bounds();
  EXPECT_TRUE(a.min.isApprox(b.min, 1e-4f) || (a.min - b.min).norm() < 1e-4f);
  EXPECT_LT((a.max - b.max).norm(), 1e-4f);
  std::filesystem::remove(p);
}

TEST(SimScenes, YUpMeshIsRotatedToZUpAndScaled) {
  sim::Mesh box;
  box.add_box({0, 0, 0}, {1, 2, 3});  // treat as a y-up file: "height" is y = 2
  const std::string p = tmp_path("yup.obj");
  sim::export_obj(box, p);
  const sim::Mesh m = sim::load_mesh(p, {.scale = 0.5, .up = sim::UpAxis::y});
  const auto b = m.bounds();
  EXPECT_NEAR(b.max.z() - b.min.z(), 1.0f, 1e-5f);  // y extent 2 x 0.5
  EXPECT_NEAR(b.max.y() - b.min.y(), 1.5f, 1e-5f);  // z extent 3 x 0.5
  std::filesystem::remove(p);
}

TEST(SimScenes, BadInputNamesFileLineAndKey) {
  try {
    sim::build_scene_from_yaml("name: x\nfloors:\n  - elevation: 0\n    outline: [0, 0, 5]\n",
                               "bad.yaml");
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    const std::string w = e.what();
    EXPECT_NE(w.find("bad.yaml:4:"), std::string::npos) << w;
    EXPECT_NE(w.find("floor.outline"), std::string::npos) << w;
  }
  try {
    sim::build_scene_from_yaml("floors:\n  - {elevation: 0, outline: [0,0,5,5], colour: red}\n",
                               "b.yaml");
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("unknown key"), std::string::npos) << e.what();
  }
  EXPECT_THROW(sim::load_scene("no_such_scene"), std::runtime_error);
  EXPECT_THROW(sim::build_scene_from_yaml("floors: [", "c.yaml"), std::runtime_error);
  // A door too narrow for the robot is refused.
  EXPECT_THROW(sim::build_scene_from_yaml(
                   "floors:\n  - {elevation: 0, outline: [0,0,5,5], walls: [{from: [2,0], to: "
                   "[2,5], doors: [{at: 1, width: 0.5}]}]}\n",
                   "d.yaml"),
               std::runtime_error);
}

TEST(SimGroundTruth, StaircaseIsTraversableAndJoinsBothFloors) {
  const sim::Scene s = sim::load_scene("test_stair");
  const sim::GroundTruth gt(s.mesh, s.start);
  ASSERT_EQ(gt.floors().size(), 2u);
  EXPECT_NEAR(gt.floors()[0].z_m, 0.0, 1e-9);
  EXPECT_NEAR(gt.floors()[1].z_m, 3.0, 1e-9);
  EXPECT_GT(gt.floors()[1].traversable_area_m2, 15.0);
  // Every tread along the flight's centre line is reachable: x = 1.8 + k*0.29 + 0.145.
  for (int k = 0; k < 17; ++k) {
    const double x = 1.8 + k * 0.29 + 0.145, z = (k + 1) * 3.0 / 18;
    const sim::VoxelKey key = sim::voxel_key({x, 1.2, z}, 0.1);
    EXPECT_TRUE(gt.reachable(key) || gt.reachable({key.x, key.y, key.z - 1}) ||
                gt.reachable({key.x, key.y, key.z + 1}))
        << "tread " << k << " z " << z;
  }
}

TEST(SimGroundTruth, RampIsTraversableAndJoinsBothFloors) {
  const sim::Scene s = sim::load_scene("test_ramp");
  const sim::GroundTruth gt(s.mesh, s.start);
  ASSERT_EQ(gt.floors().size(), 2u);
  EXPECT_NEAR(gt.floors()[1].z_m, 3.0, 1e-9);
  // Mid-ramp: x = 11.5 -> height 8.5 * tan(10 deg) = 1.4988 m.
  const sim::VoxelKey k = sim::voxel_key({11.5, 2.5, 8.5 * std::tan(10 * M_PI / 180)}, 0.1);
  EXPECT_TRUE(gt.reachable(k) || gt.reachable({k.x, k.y, k.z - 1}) ||
              gt.reachable({k.x, k.y, k.z + 1}));
}

TEST(SimGroundTruth, TableTopIsSupportButNotReachable) {
  const sim::Scene s = sim::load_scene("test_table_room");
  const sim::GroundTruth gt(s.mesh, s.start);
  const sim::VoxelKey top = sim::voxel_key({4.0, 3.0, 0.75}, 0.1);
  EXPECT_TRUE(gt.support(top));
  EXPECT_FALSE(gt.reachable(top));
  EXPECT_TRUE(gt.reachable(sim::voxel_key({4.0, 3.0, 0.0}, 0.1)));   // under the table
  EXPECT_FALSE(gt.reachable(sim::voxel_key({4.5, 1.2, 1.0}, 0.1)));  // box top
  EXPECT_FALSE(gt.reachable(sim::voxel_key({4.5, 1.2, 0.0}, 0.1)));  // inside the box
  ASSERT_EQ(gt.floors().size(), 1u);
  // Inner floor 5.6 x 4.6 = 25.76 m^2 minus the box (1 m^2), pillar (0.16), table legs, edge
  // voxels and the R_col ring (0.1 m) round walls, box, pillar and legs (~2.8 m^2).
  EXPECT_GT(gt.floors()[0].traversable_area_m2, 19.5);
  EXPECT_LT(gt.floors()[0].traversable_area_m2, 22.0);
}

TEST(SimGroundTruth, MeshWithoutStartPicksLowestFloor) {
  const sim::Scene s = sim::load_scene("test_stair");
  const sim::GroundTruth gt(s.mesh, std::nullopt);
  EXPECT_NEAR(gt.start().z, 0.0, 1e-9);
  EXPECT_EQ(gt.floors().size(), 2u);
}

// Every built-in scene: each floor of the description is found and reachable from the start.
TEST(SimGroundTruth, EveryBuiltinSceneHasAllFloorsReachable) {
  for (const auto& b : sim::builtin_scenes()) {
    SCOPED_TRACE(b.name);
    const sim::Scene s = sim::load_scene(b.name);
    ASSERT_TRUE(s.start.has_value());
    const sim::GroundTruth gt(s.mesh, s.start);
    ASSERT_EQ(gt.floors().size(), s.design_floors.size());
    for (std::size_t i = 0; i < gt.floors().size(); ++i) {
      EXPECT_NEAR(gt.floors()[i].z_m, s.design_floors[i], 0.11);
      EXPECT_GT(gt.floors()[i].traversable_area_m2, 10.0);
    }
  }
}

TEST(SimMetrics, CoverageCountsOneVoxelVerticalTolerance) {
  const sim::Scene s = sim::load_scene("test_stair");
  const sim::GroundTruth gt(s.mesh, s.start);
  const auto& all = gt.reachable_voxels();
  EXPECT_DOUBLE_EQ(sim::compute_coverage(gt, all).traversable_coverage, 1.0);
  std::vector<sim::VoxelKey> up, floor0, up2;
  for (const auto& k : all) {
    up.push_back({k.x, k.y, k.z + 1});
    up2.push_back({k.x, k.y, k.z + 2});
    if (gt.floor_of(k) == 0) floor0.push_back(k);
  }
  EXPECT_DOUBLE_EQ(sim::compute_coverage(gt, up).traversable_coverage, 1.0);
  EXPECT_LT(sim::compute_coverage(gt, up2).traversable_coverage, 0.2);
  const auto c = sim::compute_coverage(gt, floor0);
  EXPECT_DOUBLE_EQ(c.per_floor[0], 1.0);
  EXPECT_DOUBLE_EQ(c.per_floor[1], 0.0);
  EXPECT_DOUBLE_EQ(sim::compute_coverage(gt, {}).traversable_coverage, 0.0);

  sim::CoverageTimeline tl;
  tl.add(10.0, sim::compute_coverage(gt, floor0));
  tl.add(20.0, sim::compute_coverage(gt, all));
  EXPECT_DOUBLE_EQ(tl.time_to(0.95, 0), 10.0);
  EXPECT_DOUBLE_EQ(tl.time_to(0.95, 1), 20.0);
  sim::RunMetrics m;
  sim::fill_from_truth(gt, sim::compute_coverage(gt, all), tl, 0.95, m);
  EXPECT_EQ(m.floors_total, 2);
  EXPECT_EQ(m.floors_explored, 2);
  const std::string j = sim::metrics_json(m);
  for (const char* key : {"\"success\"",
                          "\"floors_total\"",
                          "\"floors_explored\"",
                          "\"exploration_time_s\"",
                          "\"trajectory_length_m\"",
                          "\"walking_time_s\"",
                          "\"traversable_volume_m3\"",
                          "\"occupied_volume_m3\"",
                          "\"traversable_coverage\"",
                          "\"per_floor\"",
                          "\"time_s\"",
                          "\"collisions\"",
                          "\"falls\"",
                          "\"safety_stops\"",
                          "\"tracking\"",
                          "\"side_p99_m\"",
                          "\"latency\"",
                          "\"method\"",
                          "\"ablation\"",
                          "\"completed\"",
                          "\"end_reason\""})
    EXPECT_NE(j.find(key), std::string::npos) << key;
}

TEST(SimRender, FloorAndSideViewsShowWallsAndTraversableGround) {
  const sim::Scene s = sim::load_scene("house");
  const sim::GroundTruth gt(s.mesh, s.start);
  const std::string dir = tmp_path("render");
  const auto files = sim::render_scene(gt, dir);
  ASSERT_EQ(files.size(), 3u);  // two floors + side view
  for (const auto& f : files) EXPECT_GT(std::filesystem::file_size(f), 100u);
  sim::View v = sim::render_floor(gt, 1);
  // The middle wall of floor 1 (x = 5) is dark, the room interior light green.
  const auto wall = v.pixel({5.0, 2.0, 3.0}), room = v.pixel({2.5, 2.0, 3.0});
  EXPECT_LT(v.image().get(wall.x(), wall.y()).g, 100);
  EXPECT_GT(v.image().get(room.x(), room.y()).g, 200);
  v.polyline({{1, 1, 3}, {3, 1, 3}, {3, 3, 3}}, {255, 0, 0});
  const auto p = v.pixel({2, 1, 3});
  EXPECT_EQ(v.image().get(p.x(), p.y()).r, 255);
  std::filesystem::remove_all(dir);
}
