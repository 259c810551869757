// LiDAR models, robot model and the lockstep WorldSim (tools/sim).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>

#include "tools/sim/lidar_model.hpp"
#include "tools/sim/ray_caster.hpp"
#include "tools/sim/robot_model.hpp"
#include "tools/sim/scene.hpp"
#include "tools/sim/world_sim.hpp"

namespace sim = storey::tools::sim;

namespace {
// Range from o along unit d to the inside of the box room (x 0.4..5.6, y 0.4..3.6, z 0..3).
double box_room_range(const Eigen::Vector3d& o, const Eigen::Vector3d& d) {
  const double lo[3] = {0.4, 0.4, 0.0}, hi[3] = {5.6, 3.6, 3.0};
  double t = 1e9;
  for (int a = 0; a < 3; ++a) {
    if (d[a] > 1e-12) t = std::min(t, (hi[a] - o[a]) / d[a]);
    if (d[a] < -1e-12) t = std::min(t, (lo[a] - o[a]) / d[a]);
  }
  return t;
}

void check_box_room(sim::LidarType type, double sigma) {
  const sim::Scene s = sim::load_scene("test_box_room");
  const sim::RayCaster rc(s.mesh);
  sim::LidarOptions o;
  o.type = type;
  o.range_noise_sigma = sigma;
  sim::LidarModel lidar(rc, o);
  const Eigen::Isometry3d body =
      Eigen::Translation3d(3.0, 2.0, 0.0) * Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ());
  sim::LidarScan scan;
  lidar.scan(
      0.0, [&](double) { return body; }, scan);
  ASSERT_GT(scan.size(), lidar.rays_per_scan() * 9 / 10);  // a closed room returns every ray
  const double tol = sigma > 0 ? 5.0 * sigma : 2e-3;
  std::size_t bad = 0;
  for (std::size_t i = 0; i < scan.size(); ++i) {
    const Eigen::Vector3d org = scan.origins_world[i].cast<double>();
    const Eigen::Vector3d p = scan.points_world[i].cast<double>();
    const double r = (p - org).norm();
    const double expect = box_room_range(org, (p - org) / r);
    if (std::abs(r - expect) > tol) ++bad;
    EXPECT_NEAR(scan.points_sensor[i].norm(), r, 1e-3);
  }
  EXPECT_EQ(bad, 0u);
}
}  // namespace

TEST(SimLidar, Vlp16RangesInBoxRoomMatchGeometry) {
  check_box_room(sim::LidarType::vlp16, 0.0);
  check_box_room(sim::LidarType::vlp16, 0.02);
}

TEST(SimLidar, Mid360RangesInBoxRoomMatchGeometry) {
  check_box_room(sim::LidarType::mid360, 0.0);
  check_box_room(sim::LidarType::mid360, 0.02);
}

TEST(SimLidar, Vlp16TimingAndRingsFollowTheFiringSequence) {
  const sim::Scene s = sim::load_scene("test_box_room");
  const sim::RayCaster rc(s.mesh);
  sim::LidarOptions o;
  o.range_noise_sigma = 0.0;
  sim::LidarModel lidar(rc, o);
  EXPECT_EQ(lidar.rays_per_scan(), 28800u);
  sim::LidarScan scan;
  const Eigen::Isometry3d body(Eigen::Translation3d(3.0, 2.0, 0.0));
  lidar.scan(
      5.0, [&](double) { return body; }, scan);
  ASSERT_EQ(scan.size(), 28800u);
  EXPECT_DOUBLE_EQ(scan.t_start, 5.0);
  for (std::size_t i = 0; i < 32; ++i) {
    const std::size_t f = i / 16, l = i % 16;
    EXPECT_EQ(scan.channels[i], l);
    EXPECT_NEAR(scan.times[i], f * 55.296e-6 + l * 2.304e-6, 1e-9);
    const auto& p = scan.points_sensor[i];
    const double el = std::asin(p.z() / p.norm()) * 180 / M_PI;
    EXPECT_NEAR(el, sim::LidarModel::kVlpElevationDeg[l], 1e-3);
  }
  EXPECT_LT(scan.times.back(), 0.1f);
}

TEST(SimLidar, Mid360CoversItsFieldOfViewAndDoesNotRepeat) {
  const sim::Scene s = sim::load_scene("test_box_room");
  const sim::RayCaster rc(s.mesh);
  sim::LidarOptions o;
  o.type = sim::LidarType::mid360;
  o.range_noise_sigma = 0.0;
  sim::LidarModel lidar(rc, o);
  EXPECT_EQ(lidar.rays_per_scan(), 20000u);
  const Eigen::Isometry3d body(Eigen::Translation3d(3.0, 2.0, 0.0));
  sim::LidarScan a, b;
  lidar.scan(
      0.0, [&](double) { return body; }, a);
  lidar.scan(
      0.1, [&](double) { return body; }, b);
  double el_min = 90, el_max = -90;
  int az_bins[36] = {};
  for (const auto& p : a.points_sensor) {
    const double el = std::asin(p.z() / p.norm()) * 180 / M_PI;
    el_min = std::min(el_min, el), el_max = std::max(el_max, el);
    ++az_bins[int((std::atan2(p.y(), p.x()) + M_PI) / (2 * M_PI) * 36) % 36];
  }
  EXPECT_NEAR(el_min, -7.0, 0.5);
  EXPECT_NEAR(el_max, 52.0, 0.5);
  for (int c : az_bins) EXPECT_GT(c, 300);
  ASSERT_EQ(a.size(), b.size());
  std::size_t same = 0;
  for (std::size_t i = 0; i < a.size(); ++i)
    same += (a.points_sensor[i] - b.points_sensor[i]).norm() < 1e-3;
  EXPECT_LT(same, a.size() / 10);  // the next frame samples other directions
}

TEST(SimLidar, DropoutRemovesAboutThatFraction) {
  const sim::Scene s = sim::load_scene("test_box_room");
  const sim::RayCaster rc(s.mesh);
  sim::LidarOptions o;
  o.dropout = 0.25;
  sim::LidarModel lidar(rc, o);
  sim::LidarScan scan;
  const Eigen::Isometry3d body(Eigen::Translation3d(3.0, 2.0, 0.0));
  lidar.scan(
      0.0, [&](double) { return body; }, scan);
  EXPECT_NEAR(double(scan.dropped) / 28800.0, 0.25, 0.02);
  EXPECT_EQ(scan.size() + scan.dropped, 28800u);
}

TEST(SimRobot, ClimbsStairsThenStopsAtWallRecordingCollision) {
  const sim::Scene s = sim::load_scene("test_stair");
  const sim::RayCaster rc(s.mesh);
  // At the foot of the flight (x = 1.8), facing +x along it.
  sim::RobotModel robot(rc, {1.2, 1.2, 0.0, 0.0});
  for (int i = 0; i < 2000 && robot.state().position.x() < 7.0; ++i) robot.step(0.01, {0.5, 0, 0});
  EXPECT_NEAR(robot.state().position.z(), 3.0, 1e-3);  // on the upper floor
  EXPECT_EQ(robot.state().falls, 0u);
  EXPECT_EQ(robot.state().collisions, 0u);
  // Keep driving: the east wall (inner face x = 7.8) stops the body (front at x + 0.35).
  for (int i = 0; i < 500; ++i) robot.step(0.01, {0.5, 0, 0});
  EXPECT_GE(robot.state().collisions, 1u);
  EXPECT_TRUE(robot.state().blocked);
  EXPECT_LT(robot.state().position.x(), 7.8 - 0.35 + 1e-3);
  EXPECT_GT(robot.state().position.x(), 7.8 - 0.35 - 0.05);
  EXPECT_TRUE(robot.state().stuck);  // commanded, no progress for 2 s
  EXPECT_EQ(robot.state().falls, 0u);
}

// A trunk follows the mean plane under its feet: a climb with the body yawed off the flight's
// axis (walking along the axis) stays clear of the nosings. With pitch and roll from four edge
// probes the attitude jumped by a full riser as a probe crossed a nosing (roll 28 deg), and a
// 2 deg skew wedged the body at the first riser.
TEST(SimRobot, ClimbsStairsWithTheBodySkewedOffTheAxis) {
  const sim::Scene s = sim::load_scene("test_stair");
  const sim::RayCaster rc(s.mesh);
  for (double deg : {-10.0, -4.0, 2.0, 6.0, 10.0}) {
    const double a = deg * M_PI / 180.0;
    sim::RobotModel robot(rc, {1.2, 1.2, 0.0, a});
    double max_roll = 0.0;
    for (int i = 0; i < 2000 && robot.state().position.x() < 6.5; ++i) {
      robot.step(0.01, {0.5 * std::cos(a), -0.5 * std::sin(a), 0});  // along +x in the world
      max_roll = std::max(max_roll, std::abs(robot.state().roll));
    }
    EXPECT_EQ(robot.state().collisions, 0u) << deg << " deg";
    EXPECT_GT(robot.state().position.z(), 2.5) << deg << " deg";
    EXPECT_LT(max_roll, 0.2) << deg << " deg";  // [rad]: no full-riser roll
  }
  // Mid-flight the trunk is pitched like the flight (0.1667 / 0.29: 29.9 deg), within 5 deg.
  sim::RobotModel robot(rc, {1.2, 1.2, 0.0, 0.0});
  for (int i = 0; i < 2000 && robot.state().position.x() < 4.0; ++i) robot.step(0.01, {0.5, 0, 0});
  EXPECT_NEAR(-robot.state().pitch, std::atan(0.1667 / 0.29), 5.0 * M_PI / 180.0);
}

TEST(SimRobot, CannotClimbABoxAndDrivesUnderATable) {
  const sim::Scene s = sim::load_scene("test_table_room");
  const sim::RayCaster rc(s.mesh);
  sim::RobotModel robot(rc, {2.5, 1.2, 0.0, 0.0});  // facing the 1 m box at x 4..5
  for (int i = 0; i < 400; ++i) robot.step(0.01, {0.5, 0, 0});
  EXPECT_GE(robot.state().collisions, 1u);
  EXPECT_NEAR(robot.state().position.z(), 0.0, 1e-6);
  EXPECT_LT(robot.state().position.x(), 4.0 - 0.35 + 1e-3);
  sim::RobotModel r2(rc, {2.5, 3.0, 0.0, 0.0});  // under the table (top at 0.75 m)
  for (int i = 0; i < 500; ++i) r2.step(0.01, {0.5, 0, 0});
  EXPECT_EQ(r2.state().collisions, 0u);
  EXPECT_GT(r2.state().position.x(), 4.0);
}

TEST(SimRobot, DrivingOffALedgeRecordsAFall) {
  const sim::Scene s = sim::build_scene_from_yaml(
      "start: [2, 2, 1.0, 0]\nfloors:\n  - elevation: 0\n    outline: [0, 0, 10, 4]\n"
      "    obstacles: [{type: box, at: [2, 2], size: [3, 3, 1.0]}]\n",
      "ledge.yaml");
  const sim::RayCaster rc(s.mesh);
  sim::RobotModel robot(rc, *s.start);
  EXPECT_NEAR(robot.state().position.z(), 1.0, 1e-5);
  for (int i = 0; i < 600; ++i) robot.step(0.01, {0.5, 0, 0});
  EXPECT_EQ(robot.state().falls, 1u);
  EXPECT_NEAR(robot.state().position.z(), 0.0, 1e-5);
}

TEST(SimRobot, AccelerationLimitsAndOdometryDrift) {
  const sim::Scene s = sim::load_scene("test_ramp");
  const sim::RayCaster rc(s.mesh);
  sim::RobotOptions o;
  o.max_accel = 1.0;
  sim::RobotModel robot(rc, {1.0, 1.0, 0.0, 0.0}, o);
  robot.step(0.25, {1.0, 0, 0});
  EXPECT_NEAR(robot.state().velocity.x(), 0.25, 1e-6);
  robot.step(1.0, {1.0, 0, 0});
  EXPECT_NEAR(robot.state().velocity.x(), 1.0, 1e-9);
  EXPECT_NEAR(robot.odometry().position.x(), robot.state().position.x(), 1e-9);
  o.odom_yaw_rate_bias = 0.01;
  sim::RobotModel drift(rc, {1.0, 1.0, 0.0, 0.0}, o);
  drift.step(1.0, {0.0, 0, 0});
  EXPECT_NEAR(drift.odometry().yaw, 0.01, 1e-6);
  EXPECT_NEAR(drift.state().yaw, 0.0, 1e-12);
}

TEST(SimRobot, WalksUpTheRampToTheUpperFloor) {
  const sim::Scene s = sim::load_scene("test_ramp");
  const sim::RayCaster rc(s.mesh);
  sim::RobotModel robot(rc, {2.0, 2.5, 0.0, 0.0});
  for (int i = 0; i < 4000 && robot.state().position.x() < 21.5; ++i) robot.step(0.01, {1.0, 0, 0});
  EXPECT_NEAR(robot.state().position.z(), 3.0, 1e-3);
  EXPECT_EQ(robot.state().collisions, 0u);
  EXPECT_EQ(robot.state().falls, 0u);
}

namespace {
std::vector<uint8_t> run_bytes(uint64_t seed, sim::LidarType type) {
  const sim::Scene s = sim::load_scene("house");
  sim::SimOptions o;
  o.seed = seed;
  o.lidar.type = type;
  o.lidar.dropout = 0.05;
  o.robot.odom_speed_noise = 0.01;
  sim::WorldSim w(s, o);
  std::vector<uint8_t> bytes;
  auto put = [&](const void* p, std::size_t n) {
    const auto* b = static_cast<const uint8_t*>(p);
    bytes.insert(bytes.end(), b, b + n);
  };
  int scans = 0;
  for (int i = 0; i < 60; ++i) {
    w.step(0.02, {0.4, 0.0, 0.3});
    if (auto sc = w.take_scan()) {
      ++scans;
      put(sc->points_world.data(), sc->size() * sizeof(Eigen::Vector3f));
      put(sc->points_sensor.data(), sc->size() * sizeof(Eigen::Vector3f));
      put(sc->times.data(), sc->size() * sizeof(float));
    }
  }
  put(w.odometry().position.data(), 3 * sizeof(double));
  EXPECT_EQ(scans, 12);
  return bytes;
}
}  // namespace

TEST(SimWorld, SameSeedSameScanBitForBit) {
  for (auto type : {sim::LidarType::vlp16, sim::LidarType::mid360}) {
    const auto a = run_bytes(7, type), b = run_bytes(7, type), c = run_bytes(8, type);
    ASSERT_EQ(a.size(), b.size());
    EXPECT_EQ(0, std::memcmp(a.data(), b.data(), a.size()));
    EXPECT_NE(a, c);
  }
}

TEST(SimWorld, ScansFollowTheMovingRobot) {
  const sim::Scene s = sim::load_scene("house");
  sim::WorldSim w(s, {});
  w.step(1.0, {0.5, 0, 0});
  auto scan = w.take_scan();
  ASSERT_TRUE(scan.has_value());
  EXPECT_NEAR(scan->t_start, 0.9, 1e-9);
  EXPECT_FALSE(w.take_scan().has_value());
  EXPECT_EQ(w.scans_completed(), 10u);
  EXPECT_EQ(w.scans_dropped(), 9u);
  // Origins move along x during the sweep (robot at ~0.5 m/s after the 0.25 s ramp-up).
  const float dx = scan->origins_world.back().x() - scan->origins_world.front().x();
  EXPECT_NEAR(dx, 0.05, 0.01);
  // Sensor frame -> world at the point's time reproduces the world point.
  EXPECT_NEAR(w.robot_state().position.x(), 2.5 + 0.5 * 0.75 + 0.0625, 0.02);
}

// Walking time counts the steps the body moved faster than kWalkingSpeed: not turning on the
// spot, not creeping, not pushing against a wall.
TEST(SimRobot, WalkingTimeCountsOnlyRealProgress) {
  const sim::Scene s = sim::load_scene("test_table_room");
  const sim::RayCaster rc(s.mesh);
  sim::RobotModel robot(rc, {2.5, 3.0, 0.0, 0.0});
  for (int i = 0; i < 100; ++i) robot.step(0.01, {0.0, 0, 0.8});  // turning on the spot
  EXPECT_EQ(robot.state().walking_s, 0.0);
  for (int i = 0; i < 100; ++i) robot.step(0.01, {0.1, 0, 0});  // creeping
  EXPECT_EQ(robot.state().walking_s, 0.0);
  sim::RobotModel walker(rc, {2.5, 1.2, 0.0, 0.0});  // facing the box at x 4..5
  for (int i = 0; i < 400; ++i) walker.step(0.01, {0.5, 0, 0});
  ASSERT_GE(walker.state().collisions, 1u);  // walked ~1.1 m, then pushed against the box
  EXPECT_GT(walker.state().walking_s, 1.5);
  EXPECT_LT(walker.state().walking_s, 3.5);
  EXPECT_LE(walker.state().walking_s * 0.5, walker.state().distance + 0.05);
}
