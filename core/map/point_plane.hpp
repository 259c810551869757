#pragma once
// Plane fit of one voxel's own points (its VoxelStats scatter): eigenvalues ascending and the
// normal (eigenvector of the smallest). Shared by the step-edge test (terrain analysis) and the
// riser normals a stair flight's axis is read from (path centring).
#include <Eigen/Eigenvalues>

#include "core/map/voxel_block.hpp"

namespace storey::core::map {

struct PointPlane {
  Eigen::Vector3d eigenvalues = Eigen::Vector3d::Zero();  // ascending, >= 0 [m^2]
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();      // unit, sign arbitrary
};

inline PointPlane point_plane(const VoxelStats& s) {
  PointPlane p;
  if (s.count == 0) return p;
  Eigen::Matrix3d c;
  c << s.m2[0], s.m2[1], s.m2[2], s.m2[1], s.m2[3], s.m2[4], s.m2[2], s.m2[4], s.m2[5];
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es;
  es.computeDirect(c / double(s.count));
  p.eigenvalues = es.eigenvalues().cwiseMax(0.0);
  p.normal = es.eigenvectors().col(0);
  return p;
}

}  // namespace storey::core::map
