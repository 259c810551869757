#pragma once
// Plane fit of one voxel's own points (its VoxelStats scatter): eigenvalues ascending and the
// normal (eigenvector of the smallest). Shared by the step-edge test (terrain analysis) and the
// riser normals a stair flight's axis is read from (path centring).
#include <cmath>

#include <Eigen/Eigenvalues>

#include "core/map/voxel_block.hpp"

namespace storey::core::map {

struct PointPlane {
  Eigen::Vector3d eigenvalues = Eigen::Vector3d::Zero();  // ascending, >= 0 [m^2]
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();      // unit, sign arbitrary
};

inline Eigen::Matrix3d scatter(const VoxelStats& s) {
  Eigen::Matrix3d c;
  c << s.m2[0], s.m2[1], s.m2[2], s.m2[1], s.m2[3], s.m2[4], s.m2[2], s.m2[4], s.m2[5];
  return c;
}

inline PointPlane plane_of_scatter(const Eigen::Matrix3d& c, double n) {
  PointPlane p;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es;
  es.computeDirect(c / n);
  p.eigenvalues = es.eigenvalues().cwiseMax(0.0);
  p.normal = es.eigenvectors().col(0);
  return p;
}

inline PointPlane point_plane(const VoxelStats& s) {
  if (s.count == 0) return PointPlane{};
  return plane_of_scatter(scatter(s), double(s.count));
}

// Points on a tilted sheet (thin across, spread along; 2 cm range noise makes risers ~1.5 cm
// thick) more than 15 deg off level: a riser, or a riser with a strip of its tread on top (a
// nosing in mid-voxel).
inline bool clear_plane(const PointPlane& p) {  // thin across, spread along: a normal
  return p.eigenvalues[1] > 0 && p.eigenvalues[0] < 0.6 * p.eigenvalues[1];
}
inline bool steep_sheet(const PointPlane& p) {
  return clear_plane(p) && std::abs(p.normal.z()) < std::cos(M_PI / 12);
}

// The plane of a riser's top piece. A rise of 0.167 m on a 0.1 m grid leaves 3.3 or 6.7 cm of
// riser in the top voxel, no taller than the range noise makes it thick: its own scatter has
// no clear normal. Then it is judged with the voxel below (its points pooled, `below` one
// voxel lower), which holds the rest of the riser. A clear plane of its own (a riser, or a
// level tread over one) stands as it is.
inline PointPlane riser_plane(const VoxelStats& s, const VoxelStats* below, double voxel_size) {
  const PointPlane own = point_plane(s);
  if (clear_plane(own) || !below || below->count == 0 || s.count == 0) return own;
  const double na = s.count, nb = below->count, n = na + nb;
  const Eigen::Vector3d ma(s.mean[0], s.mean[1], s.mean[2]);
  const Eigen::Vector3d mb(below->mean[0], below->mean[1], below->mean[2] - voxel_size);
  const Eigen::Vector3d d = ma - mb;
  const Eigen::Matrix3d c = scatter(s) + scatter(*below) + (na * nb / n) * d * d.transpose();
  return plane_of_scatter(c, n);
}

}  // namespace storey::core::map
