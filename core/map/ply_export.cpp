#include "core/map/ply_export.hpp"

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <vector>

namespace storey::core::map {

namespace {
#pragma pack(push, 1)
struct PlyVertex {
  float x, y, z;
  uint8_t r, g, b, state;
  uint8_t reasons;  // VoxelStats::kReason* bits: why tau(v) is not S_trav
  uint16_t points;  // N(v), saturated
};
#pragma pack(pop)
static_assert(sizeof(PlyVertex) == 19, "PLY vertex layout");

PlyExportResult write(const std::vector<PlyVertex>& v, const std::string& path) {
  PlyExportResult res;
  std::ofstream f(path, std::ios::binary | std::ios::trunc);
  if (!f) {
    res.error = "cannot open '" + path + "' for writing: " + std::strerror(errno);
    return res;
  }
  f << "ply\nformat binary_little_endian 1.0\ncomment storey traversability map\n"
    << "element vertex " << v.size() << "\n"
    << "property float x\nproperty float y\nproperty float z\n"
    << "property uchar red\nproperty uchar green\nproperty uchar blue\n"
    << "property uchar state\nproperty uchar reasons\nproperty ushort points\nend_header\n";
  f.write(reinterpret_cast<const char*>(v.data()), std::streamsize(v.size() * sizeof(PlyVertex)));
  if (!f) {
    res.error = "write to '" + path + "' failed";
    return res;
  }
  res.ok = true;
  res.vertices = v.size();
  return res;
}
}  // namespace

PlyExportResult write_ply_occupied(const MapView& map, const std::string& path) {
  std::vector<PlyVertex> v;
  map.for_each_occupied([&](const VoxelKey& k, const Cell& c, const VoxelStats* st) {
    const Eigen::Vector3f p = map.centre_of(k);
    PlyVertex pv{p.x(),
                 p.y(),
                 p.z(),
                 160,
                 160,
                 160,
                 uint8_t(c.state),
                 uint8_t(st ? st->reasons | ((st->shape & VoxelStats::kStepEdge) ? 0x80 : 0) : 0),
                 uint16_t(st ? std::min<uint32_t>(st->count, 65535u) : 0)};
    if (c.flags & Cell::kReachable) {
      pv.r = 40, pv.g = 90, pv.b = 230, pv.state = 4;
    } else if (c.state == TravState::kTraversable) {
      pv.r = 40, pv.g = 200, pv.b = 60;
    } else if (c.state == TravState::kUntraversable) {
      pv.r = 220, pv.g = 50, pv.b = 40;
    }
    v.push_back(pv);
  });
  return write(v, path);
}

PlyExportResult write_ply_reachable(const MapView& map, const std::string& path) {
  std::vector<PlyVertex> v;
  const float s = float(map.voxel_size_m());
  map.for_each_occupied([&](const VoxelKey& k, const Cell& c, const VoxelStats* st) {
    if (!(c.flags & Cell::kReachable)) return;
    const Eigen::Vector3f p = map.centre_of(k);
    const float h = st && st->count ? p.z() + surface_offset(st, s) : p.z() + 0.5f * s;
    v.push_back(PlyVertex{p.x(), p.y(), h, 40, 90, 230, 4, 0,
                          uint16_t(st ? std::min<uint32_t>(st->count, 65535u) : 0)});
  });
  return write(v, path);
}

}  // namespace storey::core::map
