#include "core/map/voxel_ray.hpp"

#include <random>
#include <set>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>

using storey::core::map::floor_key;
using storey::core::map::VoxelKey;
using storey::core::map::walk_ray;

namespace {
using Tup = std::tuple<int, int, int>;
std::vector<Tup> walk(double ax, double ay, double az, double bx, double by, double bz) {
  std::vector<Tup> out;
  walk_ray(ax, ay, az, bx, by, bz, [&](const VoxelKey& k) {
    out.emplace_back(k.x, k.y, k.z);
    return true;
  });
  return out;
}
}  // namespace

TEST(VoxelRay, AxisAlignedVisitsEveryVoxelButTheEnd) {
  const auto v = walk(0.5, 0.5, 0.5, 4.5, 0.5, 0.5);
  const std::vector<Tup> want = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {3, 0, 0}};
  EXPECT_EQ(v, want);
  const auto n = walk(0.5, 0.5, 0.5, 0.5, 0.5, -2.5);  // negative direction
  const std::vector<Tup> want_n = {{0, 0, 0}, {0, 0, -1}, {0, 0, -2}};
  EXPECT_EQ(n, want_n);
}

TEST(VoxelRay, SameVoxelVisitsNothing) {
  EXPECT_TRUE(walk(0.1, 0.2, 0.3, 0.9, 0.8, 0.7).empty());
}

TEST(VoxelRay, DiagonalMatchesDenseSampling) {
  // Random segments: the set of voxels the DDA visits (plus the end voxel) equals the set a very
  // dense sampling of the segment touches, and consecutive voxels are 6-connected.
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-20.0, 20.0);
  for (int trial = 0; trial < 100; ++trial) {
    const double a[3] = {u(rng), u(rng), u(rng)}, b[3] = {u(rng), u(rng), u(rng)};
    auto v = walk(a[0], a[1], a[2], b[0], b[1], b[2]);
    const VoxelKey e = floor_key(b[0], b[1], b[2]);
    v.emplace_back(e.x, e.y, e.z);
    const VoxelKey s = floor_key(a[0], a[1], a[2]);
    ASSERT_EQ(v.size(),
              size_t(std::abs(e.x - s.x) + std::abs(e.y - s.y) + std::abs(e.z - s.z) + 1));
    for (size_t i = 1; i < v.size(); ++i) {
      const int d = std::abs(std::get<0>(v[i]) - std::get<0>(v[i - 1])) +
                    std::abs(std::get<1>(v[i]) - std::get<1>(v[i - 1])) +
                    std::abs(std::get<2>(v[i]) - std::get<2>(v[i - 1]));
      ASSERT_EQ(d, 1) << "trial " << trial << " step " << i;
    }
    std::set<Tup> dda(v.begin(), v.end()), dense;
    const int n = 100000;
    for (int i = 0; i <= n; ++i) {
      const double t = double(i) / n;
      const VoxelKey k =
          floor_key(a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]), a[2] + t * (b[2] - a[2]));
      dense.emplace(k.x, k.y, k.z);
    }
    // Dense sampling can miss a voxel the segment only clips at a corner; never the reverse.
    for (const Tup& k : dense) EXPECT_TRUE(dda.count(k)) << "trial " << trial;
    EXPECT_LE(dda.size() - dense.size(), 2u) << "trial " << trial;
  }
}

TEST(VoxelRay, StopsWhenVisitorReturnsFalse) {
  int n = 0;
  const uint32_t visited =
      walk_ray(0.5, 0.5, 0.5, 10.5, 0.5, 0.5, [&](const VoxelKey&) { return ++n < 3; });
  EXPECT_EQ(n, 3);
  EXPECT_EQ(visited, 3u);
}
