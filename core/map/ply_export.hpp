#pragma once
// PLY export of the traversability map (the only file output of core/map, for reports).
#include <string>

#include "core/map/map_view.hpp"

namespace storey::core::map {

// Colours of the occupied-voxel export, by tau(v): traversable green, untraversable red,
// unobserved grey; members of C_reach blue.
struct PlyExportResult {
  bool ok = false;
  size_t vertices = 0;
  std::string error;  // names the file and what failed
};

// Binary little-endian PLY, one vertex per occupied voxel (centre, x y z float + r g b uchar,
// plus `state` uchar: 0 none, 1 unobserved, 2 traversable, 3 untraversable, 4 reachable;
// `reasons` uchar: VoxelStats::kReason* bits, 1 not top, 2 collinear, 4 cost, 8 R_col, 16 R_fall;
// `points` ushort: N(v)).
PlyExportResult write_ply_occupied(const MapView& map, const std::string& path);
// Only the members of C_reach, at their surface height.
PlyExportResult write_ply_reachable(const MapView& map, const std::string& path);

}  // namespace storey::core::map
