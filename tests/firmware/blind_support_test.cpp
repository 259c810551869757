// Blind-ring support (firmware/blind_support.hpp): where the legs stand and the LiDAR cannot see.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/map/traversability_map.hpp"
#include "firmware/blind_support.hpp"

namespace storey::firmware {
namespace {

using Eigen::Vector3f;

// Up a flight (0.29 m treads, 0.167 m risers) the foot never stays on one level for longer than a
// tread: not level. On the landing, after 0.4 m: level. Standing still on a tread: not level.
TEST(LevelTracker, LevelOnlyAfterWalkingFartherThanATreadAtOneHeight) {
  LevelTracker t;
  for (float x = 0.0f; x <= 1.0f; x += 0.05f) t.update(Vector3f(x, 0, 0));
  EXPECT_TRUE(t.level()) << "a metre on the floor";
  bool ever = false;
  for (float x = 1.0f; x < 1.0f + 10 * 0.29f; x += 0.02f) {
    t.update(Vector3f(x, 0, 0.167f * float(int((x - 1.0f) / 0.29f) + 1)));
    ever = ever || t.level();
  }
  EXPECT_FALSE(ever) << "level somewhere on the flight";
  for (int k = 0; k < 50; ++k) t.update(Vector3f(3.8f, 0, 1.67f));  // stands on a tread
  EXPECT_FALSE(t.level());
  const float landing = 1.67f + 0.167f;
  for (float x = 3.9f; x < 4.25f; x += 0.05f) t.update(Vector3f(x, 0, landing));
  EXPECT_FALSE(t.level()) << "0.35 m onto the landing";
  t.update(Vector3f(4.35f, 0.0f, landing + 0.01f));
  EXPECT_TRUE(t.level()) << "0.45 m onto the landing";
}

// A 6 x 4 m floor seen everywhere but in the blind ring; a full-height wall 1.2 m east of the
// robot, a drop 1.5 m west. The disc covers the ring, stops at the wall (line of sight) and short
// of the drop (ground seen a metre under it); once entered, the feet stand on support.
TEST(BlindSupport, DiscCoversTheBlindRingUpToWallsAndDrops) {
  core::map::TraversabilityMap m;
  std::vector<Vector3f> pts;
  for (float x = -3.0f; x <= 3.0f; x += 0.02f)
    for (float y = -2.0f; y <= 2.0f; y += 0.02f) {
      if (x * x + y * y < 1.0f) continue;  // blind ring
      if (x < 1.19f && x > -1.5f) pts.emplace_back(x, y, 0.01f);
      if (x < -1.5f) pts.emplace_back(x, y, -1.0f);  // the drop's floor
    }
  for (float y = -2.0f; y <= 2.0f; y += 0.02f)
    for (float z = 0.0f; z < 1.5f; z += 0.02f) pts.emplace_back(1.2f, y, z);
  for (int rep = 0; rep < 4; ++rep) m.insert_scan(Vector3f(0, 0, 0.5f), pts);
  const Vector3f foot(0, 0, 0);
  const auto disc = blind_support_points(m.view(), foot, 0.5, 2.0);
  auto count = [&](auto pred) { return std::count_if(disc.begin(), disc.end(), pred); };
  EXPECT_EQ(count([](const Vector3f& p) { return p.x() > 1.3f; }), 0) << "past the wall";
  EXPECT_EQ(count([](const Vector3f& p) { return p.x() < -1.6f; }), 0) << "over the drop";
  EXPECT_EQ(count([](const Vector3f& p) { return std::abs(p.z() + 0.01f) > 1e-5f; }), 0);
  // The ring itself (r < 0.9 m, 3.3 cm grid: ~2300 points) is entered whole.
  EXPECT_GT(count([](const Vector3f& p) { return p.head<2>().norm() < 0.9f; }), 2200);
  EXPECT_EQ(support_fraction(m.view(), foot), 0.0f);
  for (int rep = 0; rep < 4; ++rep) m.insert_scan(Vector3f(0, 0, 0.5f), disc);
  EXPECT_GT(support_fraction(m.view(), foot), 0.95f);
}

}  // namespace
}  // namespace storey::firmware
