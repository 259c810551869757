#include "core/map/traversability_map.hpp"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/map/ply_export.hpp"
#include "core/map/voxel_ray.hpp"
#include "tests/core_map/synthetic_world.hpp"

using namespace storey::core::map;
using Eigen::Vector3f;

namespace {
MapOptions opts() {
  MapOptions o;
  o.voxel_size_m = 0.1;
  o.min_range_m = 0.3;
  o.max_range_m = 10.0;
  o.ray_early_stop_voxels = 0;  // exact ray casting: every voxel of every ray
  return o;
}
int16_t q(float lo) {
  return int16_t(std::lround(lo * kLogOddsScale));
}
const Cell* cell_at(const TraversabilityMap& m, const VoxelKey& k) {
  BlockReader r(m.view().store());
  return r.cell(k);
}
}  // namespace

TEST(TraversabilityMap, RejectsBadOptions) {
  MapOptions o = opts();
  o.voxel_size_m = 0;
  EXPECT_THROW(TraversabilityMap{o}, std::invalid_argument);
  o = opts();
  o.max_range_m = 0.1;
  EXPECT_THROW(TraversabilityMap{o}, std::invalid_argument);
}

TEST(TraversabilityMap, SingleRayFreeVoxelsAreExactlyTheDdaVoxels) {
  TraversabilityMap m(opts());
  const Vector3f o(0.05f, 0.05f, 0.05f), p(2.34f, 1.21f, 0.47f);
  const std::vector<Vector3f> pts = {p};
  const InsertStats st = m.insert_scan(o, pts);
  EXPECT_EQ(st.hits, 1u);
  EXPECT_EQ(st.rays_cast, 1u);
  std::vector<VoxelKey> expect_free;
  walk_ray(0.5, 0.5, 0.5, 23.4, 12.1, 4.7, [&](const VoxelKey& k) {
    expect_free.push_back(k);
    return true;
  });
  const MapView v = m.view();
  for (const VoxelKey& k : expect_free) {
    EXPECT_EQ(v.occupancy(k), Occupancy::kFree);
    EXPECT_EQ(cell_at(m, k)->log_odds, q(opts().log_odds_miss));
  }
  const VoxelKey end = v.key_of(p);
  EXPECT_EQ(v.occupancy(end), Occupancy::kOccupied);
  EXPECT_EQ(cell_at(m, end)->log_odds, q(opts().log_odds_hit));
  EXPECT_EQ(v.point_count(end), 1u);
  // Count observed voxels: exactly DDA voxels + endpoint.
  size_t observed = 0;
  m.view().store().for_each([&](const VoxelBlock& b) {
    for (const Cell& c : b.cells) observed += (c.flags & Cell::kObserved) ? 1 : 0;
  });
  EXPECT_EQ(observed, expect_free.size() + 1);
  EXPECT_EQ(v.occupancy(Vector3f(-1, -1, -1)), Occupancy::kUnknown);
  EXPECT_EQ(m.occupied_voxels(), 1u);
}

TEST(TraversabilityMap, DeduplicatesPerScanAndHitWins) {
  TraversabilityMap m(opts());
  const Vector3f o(0.05f, 0.05f, 0.05f);
  // Three points in one voxel; a fourth ray passes through that voxel to a farther point.
  std::vector<Vector3f> pts = {
      {1.01f, 0.05f, 0.05f}, {1.05f, 0.06f, 0.04f}, {1.09f, 0.02f, 0.08f}, {3.05f, 0.05f, 0.05f}};
  const InsertStats st = m.insert_scan(o, pts);
  EXPECT_EQ(st.hits, 4u);
  EXPECT_EQ(st.rays_cast, 2u);  // de-duplicated by endpoint voxel
  const MapView v = m.view();
  const VoxelKey k = v.key_of(pts[0]);
  EXPECT_EQ(cell_at(m, k)->log_odds, q(opts().log_odds_hit));  // once, despite 3 hits + 1 miss
  EXPECT_EQ(v.point_count(k), 3u);                             // but every point counted
  // A voxel crossed by both rays is missed once.
  EXPECT_EQ(cell_at(m, v.key_of(Vector3f(0.55f, 0.05f, 0.05f)))->log_odds, q(opts().log_odds_miss));
}

TEST(TraversabilityMap, LogOddsClampAtBothEnds) {
  TraversabilityMap m(opts());
  const Vector3f o(0.05f, 0.05f, 0.05f);
  const std::vector<Vector3f> near = {{1.05f, 0.05f, 0.05f}}, far = {{3.05f, 0.05f, 0.05f}};
  for (int i = 0; i < 50; ++i) m.insert_scan(o, near);
  const VoxelKey k = m.view().key_of(near[0]);
  EXPECT_EQ(cell_at(m, k)->log_odds, q(opts().log_odds_max));
  for (int i = 0; i < 50; ++i) m.insert_scan(o, far);
  EXPECT_EQ(cell_at(m, k)->log_odds, q(opts().log_odds_min));
  EXPECT_EQ(m.view().occupancy(k), Occupancy::kFree);
  EXPECT_EQ(m.occupied_voxels(), 1u);  // only the far endpoint
}

TEST(TraversabilityMap, MaxRangeTruncatesAndMinRangeDrops) {
  MapOptions o = opts();
  o.max_range_m = 2.0;
  TraversabilityMap m(o);
  const Vector3f origin(0.05f, 0.05f, 0.05f);
  const std::vector<Vector3f> pts = {
      {5.05f, 0.05f, 0.05f}, {0.15f, 0.05f, 0.05f}, {NAN, 0, 0}, {1e9f, 0, 0}};
  const InsertStats st = m.insert_scan(origin, pts);
  EXPECT_EQ(st.truncated, 1u);
  EXPECT_EQ(st.dropped_min_range, 1u);
  EXPECT_EQ(st.dropped_invalid, 2u);
  EXPECT_EQ(st.hits, 0u);
  const MapView v = m.view();
  EXPECT_EQ(v.occupancy(Vector3f(1.95f, 0.05f, 0.05f)), Occupancy::kFree);
  EXPECT_EQ(v.occupancy(Vector3f(2.05f, 0.05f, 0.05f)), Occupancy::kFree);  // the max-range voxel
  EXPECT_EQ(v.occupancy(Vector3f(2.25f, 0.05f, 0.05f)), Occupancy::kUnknown);
  EXPECT_EQ(v.occupancy(Vector3f(5.05f, 0.05f, 0.05f)), Occupancy::kUnknown);
  EXPECT_EQ(m.occupied_voxels(), 0u);
  const InsertStats bad = m.insert_scan(Vector3f(NAN, 0, 0), pts);
  EXPECT_TRUE(bad.origin_invalid);
  EXPECT_EQ(bad.dropped_invalid, 4u);
}

TEST(TraversabilityMap, WelfordStatisticsMatchBatch) {
  TraversabilityMap m(opts());
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0.2001f, 0.2999f);
  std::vector<Vector3f> all;
  for (int scan = 0; scan < 20; ++scan) {
    std::vector<Vector3f> pts;
    for (int i = 0; i < 50; ++i) pts.emplace_back(u(rng) + 3.0f, u(rng), u(rng) * 0.3f + 0.2f);
    all.insert(all.end(), pts.begin(), pts.end());
    m.insert_scan(Vector3f(0.05f, 0.05f, 0.25f), pts);
  }
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Vector3f& p : all) mean += p.cast<double>();
  mean /= double(all.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const Vector3f& p : all)
    cov += (p.cast<double>() - mean) * (p.cast<double>() - mean).transpose();
  const MapView v = m.view();
  const VoxelKey k = v.key_of(all[0]);
  BlockReader r(v.store());
  const VoxelStats* s = r.stats(k);
  ASSERT_NE(s, nullptr);
  ASSERT_EQ(s->count, all.size());
  const Eigen::Vector3d c = v.centre_of(k).cast<double>();
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(s->mean[i] + c[i], mean[i], 1e-5);
  const double m2[6] = {cov(0, 0), cov(0, 1), cov(0, 2), cov(1, 1), cov(1, 2), cov(2, 2)};
  for (int i = 0; i < 6; ++i) EXPECT_NEAR(s->m2[i], m2[i], 1e-5 * std::max(1.0, std::abs(m2[i])));
}

TEST(TraversabilityMap, SnapshotIsImmutableWhileOwnerWrites) {
  TraversabilityMap m(opts());
  const Vector3f o(0.05f, 0.05f, 0.05f);
  const std::vector<Vector3f> a = {{1.05f, 0.05f, 0.05f}}, b = {{3.05f, 0.05f, 0.05f}};
  m.insert_scan(o, a);
  auto snap = m.snapshot();
  const VoxelKey k = m.view().key_of(a[0]);
  for (int i = 0; i < 10; ++i) m.insert_scan(o, b);  // clears k in the live map
  EXPECT_EQ(m.view().occupancy(k), Occupancy::kFree);
  EXPECT_EQ(snap->view().occupancy(k), Occupancy::kOccupied);
  EXPECT_EQ(snap->view().occupancy(Vector3f(3.05f, 0.05f, 0.05f)), Occupancy::kUnknown);
  EXPECT_EQ(snap->occupied_voxels(), 1u);
  EXPECT_GT(m.view().store().cow_copies(), 0u);
  auto snap2 = m.snapshot();
  EXPECT_GT(snap2->version(), snap->version());
  EXPECT_EQ(snap2->view().occupancy(k), Occupancy::kFree);
}

TEST(TraversabilityMap, RayAndBoxQueries) {
  storey::test::World w;
  w.add(storey::test::aabb({-5, -5, -0.2f}, {5, 5, 0.03f}));
  w.add(storey::test::aabb({2.0f, -1, 0}, {2.2f, 1, 2}));  // wall
  TraversabilityMap m(opts());
  for (int i = 0; i < 4; ++i) {
    const Vector3f o(0, 0, 0.5f);
    m.insert_scan(o, storey::test::scan_dense(w, o, 40000, 10 + i));
  }
  const MapView v = m.view();
  const auto hit = v.first_occupied(Vector3f(0, 0, 0.5f), Vector3f(4, 0, 0.5f));
  ASSERT_TRUE(hit.has_value());
  EXPECT_NEAR(v.centre_of(*hit).x(), 2.05f, 0.11f);
  EXPECT_FALSE(v.is_segment_free(Vector3f(0, 0, 0.5f), Vector3f(4, 0, 0.5f), true));
  EXPECT_TRUE(v.is_segment_free(Vector3f(0, 0, 0.35f), Vector3f(0, 1.5f, 0.35f), false));
  EXPECT_EQ(v.probe(Vector3f(0, 0, 0.5f), Vector3f(0, 0, 9.0f)), Occupancy::kUnknown);  // above
  std::vector<Vector3f> occ;
  EXPECT_GT(v.occupied_in_box(Vector3f(2.1f, 0, 1), Vector3f(0.3f, 0.3f, 0.3f), occ), 10u);
  for (const Vector3f& c : occ) EXPECT_NEAR(c.x(), 2.1f, 0.41f);
  const auto surf = v.support_surface_near(Vector3f(1.0f, 0.5f, 0.1f), 0.3);
  ASSERT_TRUE(surf.has_value());
  EXPECT_NEAR(surf->height_m, 0.03f, 0.02f);
  EXPECT_TRUE(v.is_free_above(surf->key, 0.4, false));
  EXPECT_FALSE(v.is_free_above(v.key_of(Vector3f(1.95f, 0.0f, 0.02f)), 0.4, true) &&
               v.is_occupied(v.key_of(Vector3f(2.05f, 0.0f, 0.05f))) &&
               !v.is_free_above(v.key_of(Vector3f(2.05f, 0.0f, 0.05f)), 0.4, true));
}

TEST(TraversabilityMap, PlyExportWritesEveryOccupiedVoxel) {
  storey::test::World w;
  w.add(storey::test::aabb({-3, -3, -0.2f}, {3, 3, 0.03f}));
  TraversabilityMap m(opts());
  const Vector3f o(0, 0, 0.5f);
  for (int i = 0; i < 3; ++i) m.insert_scan(o, storey::test::scan_dense(w, o, 30000, i));
  m.update_traversability();
  m.update_reachable(Vector3f(0, 0, 0.03f));
  const std::string path = std::string(STOREY_BINARY_DIR) + "/core_map_test.ply";
  const PlyExportResult r = write_ply_occupied(m.view(), path);
  ASSERT_TRUE(r.ok) << r.error;
  EXPECT_EQ(r.vertices, m.occupied_voxels());
  std::ifstream f(path, std::ios::binary);
  std::string line;
  std::getline(f, line);
  EXPECT_EQ(line, "ply");
  std::getline(f, line);
  EXPECT_EQ(line, "format binary_little_endian 1.0");
  const PlyExportResult rr = write_ply_reachable(m.view(), path + ".reach.ply");
  ASSERT_TRUE(rr.ok);
  EXPECT_EQ(rr.vertices, m.reachable_voxels());
  EXPECT_GT(rr.vertices, 100u);
  const PlyExportResult bad = write_ply_occupied(m.view(), "/nonexistent-dir/x.ply");
  EXPECT_FALSE(bad.ok);
  EXPECT_NE(bad.error.find("/nonexistent-dir/x.ply"), std::string::npos);
  std::remove(path.c_str());
  std::remove((path + ".reach.ply").c_str());
}

TEST(TraversabilityMap, EarlyStopRayCastingIsASubsetOfExact) {
  // ray_early_stop_voxels > 0 skips only voxels other rays of the same scan already updated:
  // same occupied voxels, free voxels a subset of the exact ones, and nearly all of them.
  const storey::test::World w = storey::test::office_box_world();
  MapOptions exact_o = opts(), fast_o = opts();
  fast_o.ray_early_stop_voxels = 4;
  TraversabilityMap exact(exact_o), fast(fast_o);
  const Vector3f o(1.0f, 0.2f, 0.5f);
  const auto pts = storey::test::scan_vlp16(w, o, 0.f, 1);
  const InsertStats se = exact.insert_scan(o, pts), sf = fast.insert_scan(o, pts);
  EXPECT_LT(sf.voxels_walked, se.voxels_walked / 2);
  EXPECT_EQ(exact.occupied_voxels(), fast.occupied_voxels());
  size_t free_exact = 0, free_fast = 0, fast_not_exact = 0;
  const MapView ve = exact.view(), vf = fast.view();
  ve.store().for_each([&](const VoxelBlock& b) {
    for (int i = 0; i < kBlockCells; ++i) {
      const VoxelKey k{(b.bx << kBlockBits) | (i >> 6), (b.by << kBlockBits) | ((i >> 3) & 7),
                       (b.bz << kBlockBits) | (i & 7)};
      free_exact += ve.occupancy(k) == Occupancy::kFree;
    }
  });
  vf.store().for_each([&](const VoxelBlock& b) {
    for (int i = 0; i < kBlockCells; ++i) {
      const VoxelKey k{(b.bx << kBlockBits) | (i >> 6), (b.by << kBlockBits) | ((i >> 3) & 7),
                       (b.bz << kBlockBits) | (i & 7)};
      if (vf.occupancy(k) != Occupancy::kFree) continue;
      ++free_fast;
      fast_not_exact += ve.occupancy(k) != Occupancy::kFree;
    }
  });
  EXPECT_EQ(fast_not_exact, 0u);
  EXPECT_GE(free_fast, free_exact * 85 / 100) << free_fast << " of " << free_exact;
}

// MapOptions::miss_needs_crossing. A corridor's walls seen from close by, then 20 scans from
// 4-8 m before its end, looking down it: rays to the walls' far parts pass within a few
// centimetres of the nearer wall voxels, inside their points' spread, and without the option
// they free them (test_ramp seed 1: the ramp's side walls freed from its foot, C_exp probes left
// through them and the frontiers came and went with the robot's distance). With it a wall voxel
// is freed only by rays crossing its plane: a door panel taken away is still cleared.
namespace {
std::vector<VoxelKey> wall_face_voxels(const TraversabilityMap& m) {  // the occupied ones
  std::vector<VoxelKey> occ;
  for (float x = 8.05f; x < 18.f; x += 0.1f)
    for (float z = 0.35f; z < 2.0f; z += 0.1f)
      for (const float y : {0.75f, -0.75f})
        if (m.view().occupancy(Vector3f(x, y, z)) == Occupancy::kOccupied)
          occ.push_back(m.view().key_of(Vector3f(x, y, z)));
  return occ;
}
}  // namespace

TEST(TraversabilityMap, RaysDownACorridorDoNotFreeItsWallsButADoorTakenAwayIsCleared) {
  storey::test::World w;
  using storey::test::aabb;
  w.add(aabb({-10, -1, -0.2f}, {20, 1, 0}));         // floor
  w.add(aabb({-10, -1.2f, 0}, {20, -0.75f, 2.5f}));  // walls 1.5 m apart
  w.add(aabb({-10, 0.75f, 0}, {20, 1.2f, 2.5f}));
  w.add(aabb({-10.2f, -1, 0}, {-10, 1, 2.5f}));  // its end wall
  storey::test::World shut = w;
  shut.add(aabb({-3, -0.75f, 0}, {-2.9f, 0.75f, 2.0f}));  // a door panel across it
  for (const bool on : {false, true}) {
    SCOPED_TRACE(on ? "map.miss_needs_crossing on" : "off");
    MapOptions o;  // defaults (30 m range, early-stop ray casting), as the robot runs them
    o.miss_needs_crossing = on;
    TraversabilityMap m(o);
    for (const float x : {6.f, 9.f, 12.f, 15.f, 18.f})
      m.insert_scan(Vector3f(x, 0, 0.55f),
                    storey::test::scan_vlp16(w, Vector3f(x, 0, 0.55f), 0.f, uint32_t(x)));
    const std::vector<VoxelKey> walls = wall_face_voxels(m);
    ASSERT_GT(walls.size(), 2000u);
    for (int k = 0; k < 20; ++k) {
      const Vector3f sensor(-4.f + 0.2f * k, 0.1f * float(k % 3), 0.55f);
      m.insert_scan(sensor,
                    storey::test::scan_vlp16(w, sensor, 0.01f * float(k), uint32_t(100 + k)));
    }
    size_t freed = 0;  // of the wall voxels the near scans left occupied
    for (const VoxelKey& k : walls) freed += m.view().occupancy(k) != Occupancy::kOccupied;
    if (on)
      EXPECT_LT(freed, walls.size() / 40);
    else  // (16 % of them: the case the option is for)
      EXPECT_GT(freed, walls.size() / 10) << "the walls were not freed: the test shows nothing";
    // The panel, seen shut from the near side, then open.
    const Vector3f at(-1.5f, 0, 0.55f);
    for (uint32_t k = 0; k < 3; ++k)
      m.insert_scan(at, storey::test::scan_vlp16(shut, at, 0.f, 200 + k));
    const Vector3f panel(-2.95f, 0.05f, 0.55f);
    ASSERT_EQ(m.view().occupancy(panel), Occupancy::kOccupied);
    for (uint32_t k = 0; k < 10; ++k)
      m.insert_scan(at, storey::test::scan_vlp16(w, at, 0.f, 300 + k));
    EXPECT_EQ(m.view().occupancy(panel), Occupancy::kFree);
  }
}

// With miss_needs_crossing a voxel of under 3 points is judged by the plane pooled with its
// neighbours', but only if its own points lie on that plane: a stray return above a floor,
// pooled with the floor below, is still cleared by the rays passing over the floor (it was not,
// and test_stair seed 1 ended "complete" at 49 s with frontiers that never resolved).
TEST(TraversabilityMap, AStrayReturnAboveAFloorIsClearedByRaysPassingOverIt) {
  storey::test::World w;
  w.add(storey::test::aabb({-10, -10, -0.2f}, {10, 10, 0.05f}));  // its points fill one voxel
  const Vector3f sensor(0, 0, 0.6f), stray(2.05f, 0.05f, 0.15f);
  for (const bool on : {false, true}) {
    SCOPED_TRACE(on ? "map.miss_needs_crossing on" : "off");
    MapOptions o;
    o.miss_needs_crossing = on;
    TraversabilityMap m(o);
    std::vector<Vector3f> first = storey::test::scan_vlp16(w, sensor, 0.f, 1);
    first.push_back(stray);
    m.insert_scan(sensor, first);
    ASSERT_EQ(m.view().occupancy(stray), Occupancy::kOccupied);
    for (uint32_t k = 0; k < 10; ++k)
      m.insert_scan(sensor, storey::test::scan_vlp16(w, sensor, 0.001f * float(k), 2 + k));
    EXPECT_EQ(m.view().occupancy(stray), Occupancy::kFree);
  }
}
