#include "core/plan/floor_tracker.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

using namespace storey::core::plan;

namespace {
// Robot climbing 17 steps of 0.17 m (one step per 0.5 s), starting at t0, walking on at
// 0.5 m/s along x.
Eigen::Vector3d stairs(double t, double t0) {
  const int steps = std::clamp(int((t - t0) / 0.5), 0, 17);
  return {0.5 * t, 0.0, 0.17 * steps};
}
// A robot standing at height z (x = 0) or walking at 0.5 m/s from x = 0 at t0.
Eigen::Vector3d at(double z) {
  return {0.0, 0.0, z};
}
Eigen::Vector3d walking(double z, double t, double t0) {
  return {0.5 * (t - t0), 0.0, z};
}
}  // namespace

TEST(FloorTracker, DetectsTheNextFloorAfterTheStairsOnceStable) {
  FloorTracker ft;
  EXPECT_TRUE(ft.update(at(0.0), 0.0));
  EXPECT_EQ(ft.current(), 0);
  bool changed = false;
  double changed_at = -1;
  for (double t = 0.1; t < 20.0; t += 0.1) {
    const bool c = ft.update(stairs(t, 1.0), t);
    if (c && !changed) changed_at = t;
    changed = changed || c;
  }
  ASSERT_TRUE(changed);
  EXPECT_EQ(ft.current(), 1);
  EXPECT_TRUE(ft.is_new_floor());
  EXPECT_EQ(ft.floors().size(), 2u);
  // On the landing (z = 2.89 from t = 9.5) after 2 m of walking (4 s > stable_s = 2 s), not
  // during the climb.
  EXPECT_GE(changed_at, 9.5 + 4.0 - 1e-9);
  EXPECT_LT(changed_at, 9.5 + 4.0 + 0.2);
  EXPECT_NEAR(ft.floor(1).z_m, 2.89, 1e-9);
}

TEST(FloorTracker, HeightsOnTheStairsNeverMakeAFloorAndGoingBackFindsTheOldOne) {
  FloorTracker ft;
  ft.update(at(0.0), 0.0);
  // Up and down a long slow ramp: never stable beyond the band.
  double t = 0;
  for (; t < 30; t += 0.1) ft.update(at(0.1 * t), t);  // 0 .. 3 m, 0.1 m/s
  for (int i = 0; i < 50; ++i, t += 0.1) ft.update(walking(3.0, t, 30.0), t);
  ASSERT_EQ(ft.current(), 1);
  for (int i = 0; i < 50; ++i, t += 0.1) ft.update(walking(0.05, t, 35.0), t);
  EXPECT_EQ(ft.current(), 0);
  EXPECT_FALSE(ft.is_new_floor());
  EXPECT_EQ(ft.floors().size(), 2u);
}

TEST(FloorTracker, NodeLabelsDzFromModesAndReferenceFloor) {
  FloorTracker ft;
  ft.update(at(0.02), 0.0);
  for (int i = 0; i < 50; ++i) ft.update(walking(3.1, 0.1 * i, 0.0), 1.0 + 0.1 * i);
  ASSERT_EQ(ft.current(), 1);
  std::vector<float> z;
  for (int i = 0; i < 50; ++i) z.push_back(0.0f + 0.01f * float(i % 3));  // floor 0 at ~0.01
  for (int i = 0; i < 50; ++i) z.push_back(3.0f + 0.01f * float(i % 3));  // floor 1 at ~3.01
  for (int i = 0; i < 10; ++i) z.push_back(0.17f * float(5 + i));         // stairs 0.85..2.38
  ft.refine(z);
  EXPECT_NEAR(ft.floor(0).z_m, 0.01, 0.005);
  EXPECT_NEAR(ft.floor(1).z_m, 3.01, 0.005);
  EXPECT_NEAR(ft.dz(0, 1), 3.0, 0.01);
  EXPECT_EQ(ft.floor_of(0.1), 0);
  EXPECT_EQ(ft.floor_of(1.5), -1);  // stairs
  EXPECT_EQ(ft.floor_of(2.9), 1);
  EXPECT_EQ(ft.choose_reference(1), 0);
  EXPECT_EQ(ft.choose_reference(0), 1);
  // A third floor above: floor 1 (adjacent) is the reference, never floor 0.
  for (int i = 0; i < 50; ++i) ft.update(walking(6.0, 0.1 * i, 0.0), 6.0 + 0.1 * i);
  ASSERT_EQ(ft.current(), 2);
  ft.floor(0).explored = true;
  EXPECT_EQ(ft.choose_reference(2), 1);
  // Between two adjacent floors the explored one wins.
  ft.floor(0).explored = false;
  ft.floor(2).explored = true;
  EXPECT_EQ(ft.choose_reference(1), 2);
}

TEST(FloorTracker, NonFiniteInputIsCountedAndIgnored) {
  FloorTracker ft;
  EXPECT_FALSE(ft.update(at(std::nan("")), 0.0));
  EXPECT_FALSE(ft.update({std::nan(""), 0.0, 0.0}, 0.0));
  EXPECT_EQ(ft.bad_input(), 2u);
  EXPECT_TRUE(ft.update(at(0.0), std::nan("")) == false);
  EXPECT_EQ(ft.current(), -1);
}

// Maze's long 5 deg and test_ramp's 10 deg ramps: the robot stops mid-ramp for 10 s (a replan, a
// safety stop) and walks on, straight up or zigzagging across the 1.5 m wide ramp. That never
// starts a floor; the floor at the top does, once the robot has walked 2 m on it. (With the
// height alone the pause made a floor mid-ramp; with a 0.12 m band over 1.5 m the zigzag made
// one at 2.6 m on the 5 deg ramp.)
TEST(FloorTracker, StandingStillOrWalkingOnARampNeverStartsAFloor) {
  for (double deg : {5.0, 10.0})
    for (double across : {0.0, 1.0}) {  // [m] lateral drift per 1.3 m of climb (diagonal)
      FloorTracker ft;
      ft.update(at(0.0), 0.0);
      const double slope = std::tan(deg * M_PI / 180.0);
      double t = 0, x = 0;
      std::vector<double> changes;
      auto walk = [&](double dx, double z_top, double dt_total) {
        const int n = int(dt_total / 0.1);
        for (int i = 0; i < n; ++i, t += 0.1) {
          x += dx / n;
          const double ph = std::fmod(x / 1.3, 2.0), y = across * (ph < 1.0 ? ph : 2.0 - ph);
          if (ft.update({x, y, std::min(z_top, slope * x)}, t)) changes.push_back(slope * x);
        }
      };
      walk(1.8 / slope, 3.0, 1.8 / slope / 0.5);  // up to 1.8 m at 0.5 m/s
      walk(0.0, 3.0, 10.0);                       // standing mid-ramp
      walk(0.1, 3.0, 0.5);                        // a few steps on
      walk(0.0, 3.0, 10.0);                       // and again
      walk(3.0 / slope - x, 3.0, 30.0);           // to the top
      EXPECT_TRUE(changes.empty())
          << deg << " deg, " << across << " m across: a floor at " << changes.front() << " m";
      EXPECT_EQ(ft.current(), 0);
      walk(3.0, 3.0, 6.0);  // on the upper floor
      ASSERT_EQ(changes.size(), 1u) << deg << " deg, " << across << " m across";
      EXPECT_EQ(ft.current(), 1);
      EXPECT_NEAR(ft.floor(1).z_m, 3.0, 1e-9);
    }
}

// Maze after a graph collapse: floor 0 keeps 3 nodes, the ramp up from it many (denser higher
// up, where the robot spent longer). Refined every cycle, floor 0's height stays where the
// robot stood on it. (Without the anchor the band followed the mode up the ramp: 1.41 m.)
TEST(FloorTracker, RefiningNeverWalksAFloorUpARamp) {
  FloorTracker ft;
  ft.update(at(0.0), 0.0);
  for (int i = 0; i < 50; ++i) ft.update(walking(3.0, 0.1 * i, 0.0), 1.0 + 0.1 * i);
  ASSERT_EQ(ft.current(), 1);
  std::vector<float> z = {0.0f, 0.01f, 0.0f};
  for (int i = 0; i <= 120; ++i)
    for (int k = 0; k < 1 + i / 40; ++k) z.push_back(0.3f + 0.01f * float(i));  // ramp 0.3..1.5
  for (int i = 0; i < 30; ++i) z.push_back(3.0f + 0.01f * float(i % 3));        // floor 1
  for (int cycle = 0; cycle < 20; ++cycle) ft.refine(z);
  EXPECT_LE(std::abs(ft.floor(0).z_m), 0.02);
  EXPECT_NEAR(ft.floor(1).z_m, 3.01, 0.01);
  EXPECT_GT(ft.dz(0, 1), 2.95);
}
