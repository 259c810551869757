// Worlds are triangle meshes: float vertices in metres, z up, triangles as vertex index triples.
// Everything the simulator does (ground truth, ray casting, pictures) works on this one type, so
// a procedural building and an imported CAD model are interchangeable.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace storey::tools::sim {

struct Aabb {
  Eigen::Vector3f min{Eigen::Vector3f::Constant(0.f)};
  Eigen::Vector3f max{Eigen::Vector3f::Constant(0.f)};
};

struct Mesh {
  std::vector<Eigen::Vector3f> vertices;           // [m], world frame, z up
  std::vector<std::array<uint32_t, 3>> triangles;  // counter-clockwise seen from outside

  std::size_t size() const { return triangles.size(); }
  bool empty() const { return triangles.empty(); }

  // Axis-aligned bounding box of all vertices (zero box when empty).
  Aabb bounds() const;
  // Appends another mesh (indices offset).
  void append(const Mesh& other);
  // Axis-aligned box [lo, hi] [m]: 12 triangles, outward normals. Degenerate boxes are skipped.
  void add_box(const Eigen::Vector3f& lo, const Eigen::Vector3f& hi);
  // Box of size (sx, sy) rotated by yaw [rad] about its centre (cx, cy), from z0 to z1 [m].
  void add_yawed_box(float cx, float cy, float sx, float sy, float yaw, float z0, float z1);
  // General hexahedron: corners 0-3 bottom (counter-clockwise seen from above), 4-7 the tops
  // above them. Used for ramps (sloped tops) and yawed boxes.
  void add_hexahedron(const std::array<Eigen::Vector3f, 8>& c);
  // Unit normal of triangle i (zero for a degenerate triangle).
  Eigen::Vector3f normal(std::size_t i) const;
  // Total surface area [m^2].
  double area() const;
  // True when every index is in range and every coordinate is finite.
  bool valid() const;
};

}  // namespace storey::tools::sim
