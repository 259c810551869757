// Eq. 1-3 and C_reach on analytic surfaces (paper Sec. III-A): what a legged robot can and
// cannot stand on, observed by a synthetic LiDAR from several poses.
#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/map/traversability_map.hpp"
#include "tests/core_map/synthetic_world.hpp"

using namespace storey::core::map;
using Eigen::Vector3f;
using storey::test::aabb;
using storey::test::World;

namespace {
constexpr float kDeg = float(M_PI) / 180.f;

void survey(TraversabilityMap& m, const World& w, const std::vector<Vector3f>& origins,
            const Vector3f& foot, int scans = 2, int rays = 60000, float el_max = 0.6f,
            float sigma = 0.003f) {
  uint32_t seed = 1;
  for (const Vector3f& o : origins)
    for (int i = 0; i < scans; ++i) {
      m.insert_scan(o, storey::test::scan_dense(w, o, rays, seed++, -1.2f, el_max, 30.f, sigma));
      m.update_traversability();
      m.update_reachable(foot);
    }
}

struct Tally {
  int samples = 0, found = 0, trav = 0, reach = 0, fall = 0, col = 0;
  std::string str() const {
    return "samples " + std::to_string(samples) + " found " + std::to_string(found) + " trav " +
           std::to_string(trav) + " reach " + std::to_string(reach) + " fall " +
           std::to_string(fall) + " col " + std::to_string(col);
  }
};

// Samples the surface z = height(x, y) on a grid over [x0,x1] x [y0,y1] and tallies the
// state of the support voxel found there.
Tally tally(const TraversabilityMap& m, float x0, float x1, float y0, float y1,
            const std::function<float(float, float)>& height, float step = 0.1f) {
  Tally t;
  const MapView v = m.view();
  BlockReader r(v.store());
  for (float x = x0 + 0.05f; x < x1; x += step)
    for (float y = y0 + 0.05f; y < y1; y += step) {
      ++t.samples;
      const auto s = v.support_surface_near(Vector3f(x, y, height(x, y)), 0.12);
      if (!s) continue;
      ++t.found;
      t.trav += s->state == TravState::kTraversable;
      t.reach += s->reachable;
      const VoxelStats* st = r.stats(s->key);
      if (st) {
        t.fall += (st->reasons & VoxelStats::kReasonFall) != 0;
        t.col += (st->reasons & VoxelStats::kReasonCollision) != 0;
      }
    }
  return t;
}

World floor_world(float half = 6.f) {
  World w;
  w.add(aabb({-half, -half, -0.3f}, {half, half, 0.03f}));
  return w;
}
// A flight of n steps rising along +x from x = 1 (1.4 m wide, on the floor) and a landing at
// its top.
World stair_world(float rise, float tread, int n) {
  World w = floor_world(8.f);
  w.stairs(1.0f, -0.7f, 0.7f, 0.03f, n, rise, tread);
  w.add(aabb({1.0f + n * tread, -0.7f, -0.3f}, {1.0f + n * tread + 2.0f, 0.7f, 0.03f + n * rise}));
  return w;
}
std::vector<Vector3f> ring_of_origins(float z, float r = 1.5f) {
  return {{0, 0, z}, {r, 0, z}, {-r, 0, z}, {0, r, z}, {0, -r, z}};
}
}  // namespace

TEST(Terrain, FlatFloorIsTraversableAndReachable) {
  TraversabilityMap m;
  survey(m, floor_world(), ring_of_origins(0.55f), Vector3f(0, 0, 0.03f));
  const Tally t = tally(m, -3, 3, -3, 3, [](float, float) { return 0.03f; });
  // The scanner does not see straight down (elevation >= -69 deg): a 0.2 m blind disc under
  // each of the 5 origins, as under a real robot.
  EXPECT_GE(t.found, t.samples * 97 / 100) << t.str();
  EXPECT_GE(t.trav, t.samples * 95 / 100) << t.str();
  EXPECT_GE(t.reach, t.samples * 95 / 100) << t.str();
  EXPECT_NEAR(m.reachable_volume_m3(), double(m.reachable_voxels()) * 1e-3, 1e-9);
  EXPECT_GT(m.traversable_volume_m3(), 36 * 0.1 * 0.9);  // >= 90% of a 6x6 m floor, 1 voxel deep
}

TEST(Terrain, Ramp20DegIsTraversableAndReachable) {
  World w = floor_world(8.f);
  const float a = 20 * kDeg;
  w.add(storey::test::ramp(1.0f, -1.0f, 1.0f, 0.03f, 3.0f, a));
  w.add(aabb({4.0f, -1.0f, -0.3f}, {6.0f, 1.0f, 0.03f + 3.0f * std::tan(a)}));  // landing
  TraversabilityMap m;
  survey(m, w,
         {{0, 0, 0.55f}, {2.0f, 0, 0.95f}, {3.0f, 0, 1.3f}, {5.0f, 0, 1.7f}, {0, 1.5f, 0.55f}},
         Vector3f(0, 0, 0.03f));
  const Tally t = tally(m, 1.4f, 3.6f, -0.6f, 0.6f,
                        [a](float x, float) { return 0.03f + (x - 1.0f) * std::tan(a); });
  EXPECT_GE(t.trav, t.samples * 90 / 100) << t.str();
  EXPECT_GE(t.reach, t.samples * 90 / 100) << t.str();
  const Tally land =
      tally(m, 4.3f, 5.7f, -0.6f, 0.6f, [a](float, float) { return 0.03f + 3.0f * std::tan(a); });
  EXPECT_GE(land.reach, land.samples * 90 / 100) << land.str();
}

TEST(Terrain, Stairs17cmAreTraversableAndReachable) {
  const float rise = 0.17f, tread = 0.30f;
  const int n = 6;
  const World w = stair_world(rise, tread, n);
  TraversabilityMap m;
  std::vector<Vector3f> origins = {{0, 0, 0.55f}, {0, 1.0f, 0.55f}};
  for (int i = 0; i <= n; i += 2)
    origins.emplace_back(1.0f + (i + 0.5f) * tread, 0, 0.6f + (i + 1) * rise);
  origins.emplace_back(1.0f + n * tread + 1.0f, 0, 0.55f + n * rise);
  survey(m, w, origins, Vector3f(0, 0, 0.03f));
  for (int i = 0; i < n; ++i) {
    // The middle of each tread, away from its nosing and riser.
    const float xs = 1.0f + i * tread + 0.1f, xe = 1.0f + (i + 1) * tread - 0.1f;
    const float h = 0.03f + (i + 1) * rise;
    const Tally t = tally(m, xs - 0.05f, xe, -0.4f, 0.4f, [h](float, float) { return h; });
    EXPECT_GE(t.trav, t.samples * 80 / 100) << "tread " << i << ": " << t.str();
    EXPECT_GE(t.reach, t.samples * 80 / 100) << "tread " << i << ": " << t.str();
  }
  const float top = 0.03f + n * rise;
  const Tally land = tally(m, 1.0f + n * tread + 0.3f, 1.0f + n * tread + 1.7f, -0.4f, 0.4f,
                           [top](float, float) { return top; });
  EXPECT_GE(land.reach, land.samples * 90 / 100) << land.str();
}

// A building's stair (0.167 m rise, 1 cm under the 0.18 m step): nosing voxels hold riser
// points below the tread, which pull their mean height down; against the mean, the tread below
// reads as a drop beyond the step and every nosing as a ledge. R_fall compares standing heights
// for that reason. (These dense synthetic scans do not reproduce the mean pulled below the step:
// the test holds with the mean too; it guards the property, the sparse VLP-16 case is in
// core/README.md, "Stairs, session 3".)
TEST(Terrain, NosingsOfA167mmStairAreNoLedge) {
  const float rise = 0.1667f, tread = 0.29f;
  const int n = 6;
  const World w = stair_world(rise, tread, n);
  TraversabilityMap m;
  // Seen as the robot climbing it sees it: from the foot and from the treads at body height.
  std::vector<Vector3f> origins = {{0.3f, 0, 0.45f}};
  for (int i = 0; i < n; ++i)
    origins.emplace_back(1.0f + (i + 0.5f) * tread, 0, 0.45f + (i + 1) * rise);
  survey(m, w, origins, Vector3f(0, 0, 0.03f));
  int fall = 0, found = 0;
  for (int i = 0; i < n; ++i) {
    const float h = 0.03f + (i + 1) * rise;
    const Tally t = tally(m, 1.0f + i * tread, 1.0f + (i + 1) * tread, -0.4f, 0.4f,
                          [h](float, float) { return h; });
    fall += t.fall;
    found += t.found;
  }
  EXPECT_GT(found, 100);
  EXPECT_EQ(fall, 0) << "tread voxels flagged R_fall";
}

TEST(Terrain, Slope45DegIsNotTraversable) {
  World w = floor_world(8.f);
  const float a = 45 * kDeg;
  w.add(storey::test::ramp(1.0f, -1.5f, 1.5f, 0.03f, 2.0f, a));
  TraversabilityMap m;
  survey(m, w, {{0, 0, 0.55f}, {0, 1.5f, 0.55f}, {0, -1.5f, 0.55f}, {-1.0f, 0, 1.5f}},
         Vector3f(0, 0, 0.03f));
  const Tally t = tally(m, 1.3f, 2.7f, -1.0f, 1.0f,
                        [a](float x, float) { return 0.03f + (x - 1.0f) * std::tan(a); });
  EXPECT_GE(t.found, t.samples * 70 / 100) << t.str();
  EXPECT_EQ(t.trav, 0) << t.str();
  EXPECT_EQ(t.reach, 0) << t.str();
}

TEST(Terrain, LedgeEdgeHasFallRisk) {
  // A 1 m high platform; the robot stands on it. Its edge voxels have no support below.
  World w = floor_world(8.f);
  w.add(aabb({-2, -2, -0.3f}, {2.02f, 2, 1.03f}));
  TraversabilityMap m;
  survey(m, w,
         {{0, 0, 1.55f},
          {1.0f, 0, 1.55f},
          {1.0f, 1.0f, 1.55f},
          {1.0f, -1.0f, 1.55f},
          {1.9f, 0.5f, 1.55f},
          {1.9f, -0.5f, 1.55f}},
         Vector3f(0, 0, 1.03f));
  // The outermost voxel column, [2.0, 2.1) in x, holding the last 2 cm of the platform: half
  // of its neighbourhood is a 1 m drop.
  const Tally edge = tally(m, 1.96f, 2.05f, -1.0f, 1.0f, [](float, float) { return 1.03f; });
  EXPECT_GE(edge.found, edge.samples * 90 / 100) << edge.str();
  EXPECT_EQ(edge.trav, 0) << edge.str();
  EXPECT_GE(edge.fall, edge.found * 90 / 100) << edge.str();
  const Tally inner = tally(m, 0.5f, 1.6f, -1.0f, 1.0f, [](float, float) { return 1.03f; });
  EXPECT_GE(inner.trav, inner.samples * 90 / 100) << inner.str();
  EXPECT_GE(inner.reach, inner.samples * 90 / 100) << inner.str();
  // The floor below the ledge is traversable but not reachable (1 m drop).
  const Tally below = tally(m, 3.0f, 4.0f, -1.0f, 1.0f, [](float, float) { return 0.03f; });
  EXPECT_GE(below.trav, below.samples * 80 / 100) << below.str();
  EXPECT_EQ(below.reach, 0) << below.str();
}

TEST(Terrain, LowCeilingCollides) {
  // A 0.1 m slab whose underside is 0.33 m above the floor (below the 0.45 m body clearance).
  World w = floor_world(8.f);
  w.add(aabb({1.5f, -1.5f, 0.36f}, {4.5f, 1.5f, 0.46f}));
  TraversabilityMap m;
  survey(m, w,
         {{0, 0, 0.2f}, {2.0f, 0, 0.2f}, {3.0f, 0.5f, 0.2f}, {4.0f, -0.5f, 0.2f}, {-1, 0, 0.6f}},
         Vector3f(0, 0, 0.03f));
  const Tally under = tally(m, 2.0f, 4.0f, -1.0f, 1.0f, [](float, float) { return 0.03f; });
  EXPECT_GE(under.found, under.samples * 90 / 100) << under.str();
  EXPECT_EQ(under.trav, 0) << under.str();
  EXPECT_GE(under.col, under.found * 95 / 100) << under.str();
  const Tally open = tally(m, -1.0f, 1.0f, -1.0f, 1.0f, [](float, float) { return 0.03f; });
  EXPECT_GE(open.trav, open.samples * 90 / 100) << open.str();
}

TEST(Terrain, TableTopIsTraversableButNotReachable) {
  World w = floor_world(8.f);
  w.add(aabb({1.0f, -0.75f, 0.72f}, {2.5f, 0.75f, 0.78f}));  // top 1.5 x 1.5 m at 0.78 m
  for (float x : {1.05f, 2.4f})
    for (float y : {-0.7f, 0.65f}) w.add(aabb({x, y, 0.0f}, {x + 0.05f, y + 0.05f, 0.72f}));
  TraversabilityMap m;
  survey(m, w, {{0, 0, 1.5f}, {0, 1.0f, 1.5f}, {3.5f, 0, 1.5f}, {1.75f, 2.0f, 1.5f}},
         Vector3f(0, 0, 0.03f));
  const Tally top = tally(m, 1.3f, 2.2f, -0.45f, 0.45f, [](float, float) { return 0.78f; });
  EXPECT_GE(top.trav, top.samples * 90 / 100) << top.str();
  EXPECT_EQ(top.reach, 0) << top.str();
  const Tally floor = tally(m, -1.0f, 0.5f, -1.0f, 1.0f, [](float, float) { return 0.03f; });
  EXPECT_GE(floor.reach, floor.samples * 90 / 100) << floor.str();
}

TEST(Terrain, FlatTreadNextToARiserKeepsItsOwnLevelPlane) {
  // A tread top at z = 0.505 (just above a voxel boundary) from x = 0.29 on; the riser below
  // its nosing at x = 0.29 (z 0.34..0.5) and the lower tread (z 0.338) before it, as a LiDAR
  // sees a stair from its foot: many riser points, few on the tread. Pooled over the 0.2 m
  // neighbourhood the plane tilts toward the riser; the tread voxel's own points are level.
  TraversabilityMap m;
  std::vector<Vector3f> pts;
  for (float y = -0.3f; y <= 0.3f; y += 0.02f) {
    for (float z = 0.345f; z < 0.5f; z += 0.01f) pts.emplace_back(0.291f, y, z);  // riser
    for (float x = 0.31f; x < 0.39f; x += 0.03f) pts.emplace_back(x, y, 0.505f);  // tread top
    for (float x = 0.02f; x < 0.28f; x += 0.05f) pts.emplace_back(x, y, 0.338f);  // lower tread
  }
  for (int rep = 0; rep < 3; ++rep) m.insert_scan(Vector3f(-0.8f, 0, 0.9f), pts);
  m.update_traversability();
  const MapView v = m.view();
  const auto s = v.support_surface_near(Vector3f(0.35f, 0.05f, 0.505f), 0.05);
  ASSERT_TRUE(s.has_value());
  EXPECT_NEAR(s->height_m, 0.505f, 0.02f);
  EXPECT_EQ(s->state, TravState::kTraversable);
  // The riser's own column ([0.2, 0.3): its sheet at the far edge, the tread behind it seen) is
  // mostly the lower tread: not a step edge, and its riser voxels stay untraversable.
  const auto r = v.support_surface_near(Vector3f(0.25f, 0.05f, 0.45f), 0.05);
  if (r) EXPECT_NE(r->state, TravState::kTraversable);
}

TEST(Terrain, RiserSmearBehindANosingStandsForTheTread) {
  // A riser at x = 0.295 from z 0.34 to a tread at exactly 0.5 (a voxel boundary), its points
  // smeared +-2 cm in x by range noise, the tread itself never hit (seen edge-on), rays grazing
  // over it to a wall beyond. The column behind the nosing, [0.3, 0.4), holds only the riser's
  // smear: a step edge standing for the tread at 0.5, traversable; the one in front is a step
  // edge too (its top is the nosing).
  TraversabilityMap m;
  std::vector<Vector3f> pts;
  int j = 0;
  for (float y = -0.3f; y <= 0.3f; y += 0.02f) {
    for (float z = 0.345f; z < 0.5f; z += 0.005f, ++j)
      pts.emplace_back(0.295f + 0.02f * float((j * 7919) % 201 - 100) / 100.0f, y, z);  // riser
    for (float x = 0.02f; x < 0.27f; x += 0.05f) pts.emplace_back(x, y, 0.338f);  // lower tread
    for (float z = 0.51f; z < 0.6f; z += 0.02f) pts.emplace_back(1.5f, y, z);     // wall beyond
  }
  for (int rep = 0; rep < 3; ++rep) m.insert_scan(Vector3f(-0.8f, 0, 0.6f), pts);
  m.update_traversability();
  const MapView v = m.view();
  BlockReader rd(v.store());
  const VoxelKey behind{3, 0, 4};  // x [0.3, 0.4), y [0, 0.1), z [0.4, 0.5)
  ASSERT_EQ(v.occupancy(behind), Occupancy::kOccupied);
  ASSERT_NE(rd.stats(behind), nullptr);
  EXPECT_TRUE(rd.stats(behind)->shape & VoxelStats::kStepEdge);
  EXPECT_EQ(v.state(behind), TravState::kTraversable);
  ASSERT_TRUE(v.surface_height_m(behind).has_value());
  EXPECT_NEAR(*v.surface_height_m(behind), 0.5f, 0.02f);
  // The lower tread, 0.16 below the nosing (within the step: C_reach climbs on).
  const VoxelKey lower{1, 0, 3};  // the lower tread, x [0.1, 0.2), z [0.3, 0.4)
  EXPECT_EQ(v.state(lower), TravState::kTraversable);
}

TEST(Terrain, SteepSlopeTopIsNotAStepEdge) {
  // A 50 deg slope's top voxels hold tilted sheets under free space like a riser's, but the
  // next column up rises by ~0.12 m: a slope, never a step edge, never traversable.
  TraversabilityMap m;
  std::vector<Vector3f> pts;
  const float t = std::tan(50.0f * float(M_PI) / 180.0f);
  for (float y = -0.5f; y <= 0.5f; y += 0.02f)
    for (float x = 0.0f; x < 1.0f; x += 0.01f) pts.emplace_back(x, y, 0.03f + x * t);
  for (int rep = 0; rep < 3; ++rep) m.insert_scan(Vector3f(-1.5f, 0, 0.6f), pts);
  m.update_traversability();
  const MapView v = m.view();
  BlockReader rd(v.store());
  int edges = 0, trav = 0, found = 0;
  for (float x = 0.15f; x < 0.9f; x += 0.1f) {
    const auto s = v.support_surface_near(Vector3f(x, 0.05f, 0.03f + x * t), 0.1);
    if (!s) continue;
    ++found;
    const VoxelStats* st = rd.stats(s->key);
    edges += st && (st->shape & VoxelStats::kStepEdge);
    trav += s->state == TravState::kTraversable;
  }
  EXPECT_GE(found, 5);
  EXPECT_EQ(edges, 0);
  EXPECT_EQ(trav, 0);
}

// A floor exactly on a voxel boundary (z = 0, as in the simulator's scenes): range noise puts a
// few of its points into the voxel above. That spill, under N_min over a well-observed voxel, is
// the same floor, not an under-observed surface (it read S_unobs and made frontiers in explored
// corridors). Columns observed sparsely all the way down stay S_unobs. Experimental, off by
// default (MapOptions::spill_is_surface): off, the spills stay S_unobs.
TEST(Terrain, FloorOnAVoxelBoundaryIsNotUnderObservedWhereItSpills) {
  for (const bool on : {true, false}) {
    SCOPED_TRACE(on ? "map.spill_is_surface on" : "off");
    World w;
    w.add(aabb({-6, -6, -0.3f}, {6, 6, 0.0f}));
    MapOptions opt;
    opt.spill_is_surface = on;
    TraversabilityMap m(opt);
    survey(m, w, ring_of_origins(0.55f), Vector3f(0, 0, 0), 2, 60000, 0.6f, 0.01f);
    const MapView v = m.view();
    BlockReader r(v.store());
    int spills = 0, spills_trav = 0, sparse = 0, sparse_unobserved = 0;
    for (float x = -2.95f; x < 3; x += 0.1f)
      for (float y = -2.95f; y < 3; y += 0.1f) {
        const auto s = v.support_surface_near(Vector3f(x, y, 0.0f), 0.12);
        if (!s) continue;
        const VoxelStats* st = r.stats(s->key);
        if (!st || st->count >= 5) continue;
        const VoxelStats* below = r.stats({s->key.x, s->key.y, s->key.z - 1});
        if (s->key.z == 0 && below && below->count >= 5) {
          ++spills;
          spills_trav += s->state == TravState::kTraversable;
        } else {
          ++sparse;
          sparse_unobserved += s->state == TravState::kUnobserved;
        }
      }
    EXPECT_GT(spills, 50) << "the noise spilled too little to test anything";
    EXPECT_EQ(spills_trav, on ? spills : 0);  // off: every spill reads S_unobs
    EXPECT_GT(sparse, 0);
    EXPECT_EQ(sparse_unobserved, sparse);
  }
}

// A ceiling seen from the floor below: its slab's inside and the floor on top are never observed,
// so the underside's voxels have no occupied voxel above them. Without a point seen from above
// they read as a top surface: a phantom floor under the real one (teaching_building seed 1: over
// the whole building, every frontier on it unreachable). With MapOptions::floor_seen_from_above
// the underside is no floor; the slab's top, once seen from above, is.
TEST(Terrain, ACeilingSeenFromBelowIsNoFloorUntilSeenFromAbove) {
  World w;
  w.add(aabb({-6, -6, -0.3f}, {6, 6, 0.0f}));  // floor
  w.add(aabb({-6, -6, 3.0f}, {6, 6, 3.2f}));   // the slab: ceiling at 3.0, the next floor at 3.2
  const auto underside = [](float, float) { return 3.0f; };
  const auto top = [](float, float) { return 3.2f; };
  for (const bool on : {true, false}) {
    SCOPED_TRACE(on ? "map.floor_seen_from_above on" : "off");
    MapOptions opt;
    opt.spill_is_surface = opt.miss_needs_crossing = true;  // as in config/default.yaml
    opt.floor_seen_from_above = on;
    TraversabilityMap m(opt);
    survey(m, w, ring_of_origins(0.55f), Vector3f(0, 0, 0), 2, 60000, 1.2f, 0.01f);
    const Tally floor = tally(m, -2, 2, -2, 2, [](float, float) { return 0.0f; });
    EXPECT_GE(floor.trav, floor.samples * 9 / 10) << floor.str();  // the floor stays a floor
    const Tally below = tally(m, -2, 2, -2, 2, underside);
    EXPECT_GE(below.found, below.samples * 9 / 10) << below.str();
    if (on)
      EXPECT_EQ(below.trav, 0) << below.str();
    else
      EXPECT_GE(below.trav, below.samples / 2) << below.str();  // the phantom floor
    // Then seen from above (a robot on the slab, through no opening: its scans see its top).
    World upper;
    upper.add(aabb({-6, -6, 3.0f}, {6, 6, 3.2f}));
    survey(m, upper, ring_of_origins(3.75f), Vector3f(0, 0, 3.2f), 2, 60000, 0.6f, 0.01f);
    const Tally above = tally(m, -2, 2, -2, 2, top);
    EXPECT_GE(above.trav, above.samples * 9 / 10) << above.str();
  }
}

// A ramp rising above the sensor, seen from its foot only: its rays rise, but less steeply than
// the ramp, and hit its top. It stays a floor with MapOptions::floor_seen_from_above (a test of
// the sensor's height alone would drop it: here all of it past x = 2.1 m).
TEST(Terrain, ARampRisingAboveTheSensorIsAFloorSeenFromItsFoot) {
  World w = floor_world(10.f);
  const float a = 25 * kDeg;
  w.add(storey::test::ramp(1.0f, -1.0f, 1.0f, 0.03f, 4.0f, a));
  const auto ramp_z = [a](float x, float) { return 0.03f + (x - 1.0f) * std::tan(a); };
  int trav[2] = {0, 0};
  for (const bool on : {true, false}) {
    SCOPED_TRACE(on ? "map.floor_seen_from_above on" : "off");
    MapOptions opt;
    opt.spill_is_surface = opt.miss_needs_crossing = true;
    opt.floor_seen_from_above = on;
    TraversabilityMap m(opt);
    survey(m, w, {{-0.5f, 0, 0.55f}, {-0.5f, 0.8f, 0.55f}, {-0.5f, -0.8f, 0.55f}},
           Vector3f(-0.5f, 0, 0.03f), 2, 90000);
    const Tally t = tally(m, 2.3f, 4.3f, -0.6f, 0.6f, ramp_z);  // above the sensor's 0.55 m
    EXPECT_GE(t.trav, t.samples / 2) << t.str();
    trav[on] = t.trav;
  }
  EXPECT_GE(trav[1], trav[0] * 95 / 100);
}

// A patch whose points first came with rays rising 0.04 (from below: an edge's top grazed from the
// flight under it), then with level rays from fewer scans (N(v) does not double): it is judged
// again at once and reads as a floor (the top of the teaching building's flight, seen from its
// last treads, stayed S_untrav and the upper floor was left).
TEST(Terrain, ASurfaceSeenFromBelowThenFromItsOwnLevelIsAFloorAtOnce) {
  MapOptions opt;
  opt.floor_seen_from_above = true;
  TraversabilityMap m(opt);
  std::vector<Vector3f> patch;
  for (float x = 4.51f; x < 5.5f; x += 0.02f)
    for (float y = -0.49f; y < 0.5f; y += 0.02f) patch.emplace_back(x, y, 0.75f);
  for (int rep = 0; rep < 3; ++rep) m.insert_scan(Vector3f(0, 0, 0.55f), patch);
  m.update_traversability();
  const auto top = [](float, float) { return 0.75f; };
  const Tally below = tally(m, 4.6f, 5.4f, -0.4f, 0.4f, top);
  EXPECT_EQ(below.trav, 0) << below.str();
  EXPECT_EQ(below.found, below.samples) << below.str();
  m.insert_scan(Vector3f(0, 0, 0.75f), patch);
  m.update_traversability();
  const Tally level = tally(m, 4.6f, 5.4f, -0.4f, 0.4f, top);
  EXPECT_EQ(level.trav, level.samples) << level.str();
}
