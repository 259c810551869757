// riser_plane (core/map/point_plane.hpp): a riser's short top piece judged with the riser below.
#include <random>

#include <gtest/gtest.h>

#include "core/map/point_plane.hpp"

namespace storey::core::map {
namespace {

// Points of a riser in the plane y = y0 (voxel-centre frame, 0.1 m voxels) from z0 to z1,
// spread over x, with 1.7 cm of range noise across it (rays hit it head-on).
VoxelStats riser(float z0, float z1, float y0, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-0.05f, 0.05f), h(z0, z1);
  std::normal_distribution<float> n(0.0f, 0.017f);
  VoxelStats s;
  for (int i = 0; i < 2000; ++i) s.add(u(rng), y0 + n(rng), h(rng));
  return s;
}

TEST(RiserPlane, ShortTopPieceIsJudgedWithTheRiserBelow) {
  // A 0.167 m rise on a 0.1 m grid: 6.7 cm of riser in the top voxel, the full voxel below.
  const VoxelStats top = riser(-0.05f, 0.017f, 0.018f, 1);
  const VoxelStats below = riser(-0.05f, 0.05f, 0.018f, 2);
  EXPECT_FALSE(steep_sheet(point_plane(top))) << "no clear normal on its own";
  const PointPlane p = riser_plane(top, &below, 0.1);
  EXPECT_TRUE(steep_sheet(p));
  EXPECT_GT(std::abs(p.normal.y()), 0.95) << p.normal.transpose();
  // Nothing below: as it is.
  EXPECT_FALSE(steep_sheet(riser_plane(top, nullptr, 0.1)));
}

TEST(RiserPlane, ALevelTreadOverARiserStaysLevel) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-0.05f, 0.05f);
  std::normal_distribution<float> n(0.0f, 0.004f);
  VoxelStats tread;
  for (int i = 0; i < 2000; ++i) tread.add(u(rng), u(rng), -0.03f + n(rng));
  const VoxelStats below = riser(-0.05f, 0.05f, 0.018f, 4);
  const PointPlane p = riser_plane(tread, &below, 0.1);
  EXPECT_GT(std::abs(p.normal.z()), 0.99) << p.normal.transpose();
  EXPECT_FALSE(steep_sheet(p));
}

}  // namespace
}  // namespace storey::core::map
