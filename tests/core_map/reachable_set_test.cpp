// C_reach (paper Sec. III-A): multi-floor region growing and incremental maintenance.
#include <algorithm>
#include <random>
#include <set>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>

#include "core/map/traversability_map.hpp"
#include "tests/core_map/synthetic_world.hpp"

using namespace storey::core::map;
using Eigen::Vector3f;
using storey::test::aabb;
using storey::test::World;

namespace {
using Key3 = std::tuple<int, int, int>;

std::set<Key3> flagged_reachable(const TraversabilityMap& m) {
  std::set<Key3> out;
  m.view().for_each_occupied([&](const VoxelKey& k, const Cell& c, const VoxelStats*) {
    if (c.flags & Cell::kReachable) out.emplace(k.x, k.y, k.z);
  });
  return out;
}
std::set<Key3> scratch_reachable(const TraversabilityMap& m) {
  std::set<Key3> out;
  for (const VoxelKey& k : m.grow_from_scratch(m.reach_roots())) out.emplace(k.x, k.y, k.z);
  return out;
}

// Two storeys 3 m apart (slab tops at 0.03 and 3.03 m), joined by a straight flight of 18
// steps (rise 0.1667 m, tread 0.28 m) under a stairwell opening.
World two_floor_building() {
  World w;
  w.add(aabb({-6, -4, -0.3f}, {6, 4, 0.03f}));  // ground floor
  // Upper slab with a stairwell hole x in [-2, 3.04], y in [2.6, 4].
  w.add(aabb({-6, -4, 2.83f}, {6, 2.6f, 3.03f}));
  w.add(aabb({-6, 2.6f, 2.83f}, {-2, 4, 3.03f}));
  w.add(aabb({3.04f, 2.6f, 2.83f}, {6, 4, 3.03f}));
  w.stairs(-2.0f, 2.7f, 3.9f, 0.03f, 18, 3.0f / 18.f, 0.28f);
  w.add(aabb({-6.2f, -4.2f, -0.3f}, {-6, 4.2f, 6}));  // outer walls
  w.add(aabb({6, -4.2f, -0.3f}, {6.2f, 4.2f, 6}));
  w.add(aabb({-6, -4.2f, -0.3f}, {6, -4, 6}));
  w.add(aabb({-6, 4, -0.3f}, {6, 4.2f, 6}));
  w.add(aabb({-6, 2.5f, 0.03f}, {-2.5f, 2.6f, 2.83f}));  // wall beside the stairs, ground floor
  return w;
}
}  // namespace

TEST(ReachableSet, TwoFloorsStackedAndJoinedByStairs) {
  const World w = two_floor_building();
  TraversabilityMap m;
  // The robot walks a lawnmower path on the ground floor, climbs, and walks the upper floor.
  std::vector<Vector3f> path;
  for (float y : {-2.5f, 0.5f})
    for (float x = -4.5f; x <= 4.6f; x += 1.5f) path.emplace_back(y < 0 ? x : -x, y, 0.55f);
  path.emplace_back(-3.0f, 1.5f, 0.55f);
  path.emplace_back(-3.0f, 3.3f, 0.55f);
  for (int i = 0; i < 18; i += 3)
    path.emplace_back(-2.0f + (i + 0.5f) * 0.28f, 3.3f, 0.03f + (i + 1) * (3.0f / 18.f) + 0.52f);
  path.emplace_back(4.5f, 3.3f, 3.55f);
  for (float y : {0.5f, -2.5f})
    for (float x = 4.5f; x >= -4.6f; x -= 1.5f) path.emplace_back(y > 0 ? x : -x, y, 3.55f);
  uint32_t seed = 1;
  for (const Vector3f& o : path)
    for (int i = 0; i < 2; ++i) {
      m.insert_scan(o, storey::test::scan_dense(w, o, 40000, seed++, -1.2f, 1.2f));
      m.update_traversability();
      m.update_reachable(o - Vector3f(0, 0, 0.52f));  // the robot walks the path
    }
  const MapView v = m.view();
  // Both floors exist over the same (x, y), and both are reachable through the stairs.
  int both = 0, samples = 0, lo_reach = 0, hi_reach = 0, lo_found = 0, hi_found = 0;
  for (float x = -5.45f; x < 5.5f; x += 0.5f)
    for (float y = -3.45f; y < 2.3f; y += 0.5f) {
      ++samples;
      const auto lo = v.support_surface_near(Vector3f(x, y, 0.03f), 0.12);
      const auto hi = v.support_surface_near(Vector3f(x, y, 3.03f), 0.12);
      if (getenv("STOREY_DEBUG")) {
        BlockReader r(v.store());
        for (const auto& s : {lo, hi})
          if (s && !s->reachable) {
            const VoxelStats* st = r.stats(s->key);
            printf("%.2f %.2f h %.2f state %d reasons %d N %u cost %.2f\n", x, y, s->height_m,
                   int(s->state), st ? st->reasons : -1, st ? st->count : 0, st ? st->cost : 0);
          }
      }
      lo_found += lo.has_value();
      hi_found += hi.has_value();
      lo_reach += lo && lo->reachable;
      hi_reach += hi && hi->reachable;
      if (lo && hi && lo->reachable && hi->reachable) {
        EXPECT_EQ(lo->state, TravState::kTraversable);
        EXPECT_EQ(hi->state, TravState::kTraversable);
        EXPECT_NEAR(lo->height_m, 0.03f, 0.03f);
        EXPECT_NEAR(hi->height_m, 3.03f, 0.03f);
        ++both;
      }
    }
  // Sparse corners and blind discs under the scan poses leave some samples unobserved.
  EXPECT_GE(lo_reach, samples * 75 / 100) << "ground floor reachable " << lo_reach;
  EXPECT_GE(hi_reach, samples * 75 / 100) << "upper floor reachable " << hi_reach;
  EXPECT_GE(both, samples * 55 / 100) << both << " of " << samples;
  // Every tread of the flight is in C_reach (somewhere across its width: the scan poses
  // leave a blind disc on the tread right under them).
  for (int i = 0; i < 18; ++i) {
    int reach = 0;
    for (float y : {2.95f, 3.15f, 3.3f, 3.45f, 3.65f}) {
      const auto s = v.support_surface_near(
          Vector3f(-2.0f + (i + 0.5f) * 0.28f, y, 0.03f + (i + 1) * (3.0f / 18.f)), 0.1);
      reach += s && s->reachable;
      if (getenv("STOREY_DEBUG") && s) {
        BlockReader r(v.store());
        const VoxelStats* st = r.stats(s->key);
        printf("tread %d y %.2f h %.3f state %d reach %d reasons %d N %u cost %.2f\n", i, y,
               s->height_m, int(s->state), s->reachable, st ? st->reasons : -1, st ? st->count : 0,
               st ? st->cost : 0.f);
      }
    }
    EXPECT_GE(reach, 3) << "tread " << i;
  }
  EXPECT_EQ(flagged_reachable(m), scratch_reachable(m));
  EXPECT_EQ(m.reachable_voxels(), flagged_reachable(m).size());
}

TEST(ReachableSet, IncrementalEqualsFromScratchUnderRandomUpdates) {
  // Obstacles appear and disappear on a floor with a small flight of stairs; after every scan
  // the incrementally maintained C_reach must equal a region grow from scratch.
  std::mt19937 rng(42);
  std::uniform_real_distribution<float> ux(-3.5f, 3.5f), us(0.2f, 0.9f), uh(0.05f, 0.8f);
  std::vector<storey::test::Box> obstacles;
  for (int i = 0; i < 10; ++i) {
    const float x = ux(rng), y = ux(rng), sx = us(rng), sy = us(rng), h = uh(rng);
    obstacles.push_back(aabb({x, y, 0.0f}, {x + sx, y + sy, 0.03f + h}));
  }
  std::vector<bool> present(obstacles.size(), false);
  TraversabilityMap m;
  uint32_t seed = 100;
  size_t largest = 0;
  int shrinks = 0;
  for (int step = 0; step < 30; ++step) {
    const size_t which = rng() % obstacles.size();
    present[which] = !present[which];
    World w;
    w.add(aabb({-5, -5, -0.3f}, {5, 5, 0.03f}));
    w.stairs(-4.5f, -4.5f, -3.0f, 0.03f, 4, 0.15f, 0.3f);
    for (size_t i = 0; i < obstacles.size(); ++i)
      if (present[i]) w.add(obstacles[i]);
    const Vector3f o(ux(rng) * 0.8f, ux(rng) * 0.8f, 0.55f);
    m.insert_scan(o, storey::test::scan_dense(w, o, 40000, seed++));
    m.update_traversability();
    const size_t before = m.reachable_voxels();
    const ReachUpdateStats st = m.update_reachable(Vector3f(0, 0, 0.03f));
    shrinks += st.orphaned > 0 && !st.full_regrow;
    largest = std::max(largest, size_t(m.reachable_voxels()));
    (void)before;
    const auto inc = flagged_reachable(m);
    ASSERT_EQ(inc, scratch_reachable(m)) << "step " << step;
    ASSERT_EQ(m.reachable_voxels(), inc.size()) << "step " << step;
  }
  EXPECT_GT(largest, 3000u);
  EXPECT_GT(shrinks, 0);  // the decremental path was exercised
}

// C_reach strides over one column up or down a step (a stair tread the LiDAR saw edge-on, its
// voxels grazed free), but not over a hole in level ground, nor over anything standing in it.
TEST(ReachableSet, StridesOverAnUnseenStripOnlyUpOrDownAStep) {
  auto reaches_far_patch = [](float far_z, bool wall) {
    TraversabilityMap m;
    std::vector<Vector3f> pts;
    for (float y = -0.5f; y <= 0.5f; y += 0.02f) {
      for (float x = -1.0f; x < 0.49f; x += 0.02f) pts.emplace_back(x, y, 0.02f);
      for (float x = 0.61f; x < 1.5f; x += 0.02f) pts.emplace_back(x, y, far_z);
      if (wall)
        for (float z = 0.05f; z < 0.8f; z += 0.02f) pts.emplace_back(0.55f, y, z);
    }
    for (int rep = 0; rep < 4; ++rep) m.insert_scan(Vector3f(0.0f, 0.0f, 1.0f), pts);
    m.update_traversability();
    m.update_reachable(Vector3f(0.0f, 0.0f, 0.02f));
    const MapView v = m.view();
    EXPECT_TRUE(v.is_reachable(v.key_of(Vector3f(0.2f, 0.05f, 0.01f))));
    const VoxelKey far = v.key_of(Vector3f(1.0f, 0.05f, far_z - 0.01f));
    EXPECT_EQ(v.state(far), TravState::kTraversable);
    EXPECT_EQ(flagged_reachable(m), scratch_reachable(m));
    return v.is_reachable(far);
  };
  EXPECT_TRUE(reaches_far_patch(0.17f, false)) << "no stride up a 0.15 m step";
  EXPECT_FALSE(reaches_far_patch(0.02f, false)) << "a hole in level ground was bridged";
  EXPECT_FALSE(reaches_far_patch(0.17f, true)) << "strode through a wall";
}

// MapOptions::seed_under_feet (with plan.climb_blind): a robot standing on support C_reach never
// reached (a landing after a blind climb), a step above a C_reach member within the seed radius,
// seeds C_reach under its feet; without the option the seed stays on the component it came from.
TEST(ReachableSet, SeedUnderTheFeetAfterAClimbOnlyWithTheOption) {
  auto landing_reached = [](bool under_feet) {
    MapOptions o;
    o.seed_under_feet = under_feet;
    TraversabilityMap m(o);
    std::vector<Vector3f> pts;
    for (float y = -0.5f; y <= 0.5f; y += 0.02f) {
      for (float x = -1.5f; x < 0.49f; x += 0.02f) pts.emplace_back(x, y, 0.02f);  // flight top
      for (float z = 0.05f; z < 0.8f; z += 0.02f) pts.emplace_back(0.55f, y, z);   // no way across
      for (float x = 0.61f; x < 2.0f; x += 0.02f) pts.emplace_back(x, y, 0.17f);   // landing
    }
    for (int rep = 0; rep < 4; ++rep) m.insert_scan(Vector3f(0.5f, 0.0f, 1.5f), pts);
    m.update_traversability();
    m.update_reachable(Vector3f(-0.5f, 0.0f, 0.02f));
    const MapView v = m.view();
    const VoxelKey landing = v.key_of(Vector3f(1.2f, 0.05f, 0.16f));
    EXPECT_EQ(v.state(landing), TravState::kTraversable);
    EXPECT_FALSE(v.is_reachable(landing));
    m.update_reachable(Vector3f(0.9f, 0.0f, 0.17f));  // the robot now stands on the landing
    EXPECT_EQ(flagged_reachable(m), scratch_reachable(m));
    return m.view().is_reachable(landing);
  };
  EXPECT_FALSE(landing_reached(false));
  EXPECT_TRUE(landing_reached(true));
}
