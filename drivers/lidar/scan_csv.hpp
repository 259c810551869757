#pragma once
// Scan export for `storey replay --export-scans DIR`: one CSV per scan, numbered from 0, points in
// packet order, sensor frame, Velodyne's convention. Columns: x,y,z [m], intensity, ring,
// time offset [ns] from the scan start. File I/O: call from a non-RT thread.
#include <cstdio>
#include <string>

#include "drivers/lidar/scan_assembler.hpp"

namespace storey::drivers::lidar {

// DIR/scan_000000.csv for index 0.
inline std::string scan_csv_path(const std::string& dir, uint64_t index) {
  char name[32];
  std::snprintf(name, sizeof(name), "scan_%06llu.csv", static_cast<unsigned long long>(index));
  return dir + "/" + name;
}

// Writes one scan; false with a reason naming the file.
inline bool write_scan_csv(const std::string& path, const Scan& scan, std::string* error) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (f == nullptr) {
    if (error != nullptr) *error = path + ": cannot write";
    return false;
  }
  std::fputs("x,y,z,intensity,ring,time_offset_ns\n", f);
  for (const LidarPoint& p : scan.points) {
    std::fprintf(f, "%.6f,%.6f,%.6f,%.0f,%u,%d\n", p.x, p.y, p.z, p.intensity,
                 static_cast<unsigned>(p.ring), p.time_offset_ns);
  }
  const bool ok = std::fclose(f) == 0;
  if (!ok && error != nullptr) *error = path + ": write failed";
  return ok;
}

}  // namespace storey::drivers::lidar
