#include "tools/sim/mesh.hpp"

#include <Eigen/Geometry>
#include <cmath>

namespace storey::tools::sim {

Aabb Mesh::bounds() const {
  Aabb b;
  if (vertices.empty()) return b;
  b.min = b.max = vertices.front();
  for (const auto& v : vertices) {
    b.min = b.min.cwiseMin(v);
    b.max = b.max.cwiseMax(v);
  }
  return b;
}

void Mesh::append(const Mesh& other) {
  const auto off = static_cast<uint32_t>(vertices.size());
  vertices.insert(vertices.end(), other.vertices.begin(), other.vertices.end());
  triangles.reserve(triangles.size() + other.triangles.size());
  for (const auto& t : other.triangles) triangles.push_back({t[0] + off, t[1] + off, t[2] + off});
}

void Mesh::add_hexahedron(const std::array<Eigen::Vector3f, 8>& c) {
  const auto o = static_cast<uint32_t>(vertices.size());
  vertices.insert(vertices.end(), c.begin(), c.end());
  // Faces as quads (outward, counter-clockwise seen from outside), split into two triangles.
  static constexpr std::array<std::array<uint32_t, 4>, 6> kQuads = {{
      {0, 3, 2, 1},  // bottom (seen from below)
      {4, 5, 6, 7},  // top
      {0, 1, 5, 4},
      {1, 2, 6, 5},
      {2, 3, 7, 6},
      {3, 0, 4, 7},
  }};
  for (const auto& q : kQuads) {
    triangles.push_back({o + q[0], o + q[1], o + q[2]});
    triangles.push_back({o + q[0], o + q[2], o + q[3]});
  }
}

void Mesh::add_box(const Eigen::Vector3f& lo, const Eigen::Vector3f& hi) {
  if (!((hi.array() > lo.array()).all())) return;
  add_hexahedron({Eigen::Vector3f(lo.x(), lo.y(), lo.z()), Eigen::Vector3f(hi.x(), lo.y(), lo.z()),
                  Eigen::Vector3f(hi.x(), hi.y(), lo.z()), Eigen::Vector3f(lo.x(), hi.y(), lo.z()),
                  Eigen::Vector3f(lo.x(), lo.y(), hi.z()), Eigen::Vector3f(hi.x(), lo.y(), hi.z()),
                  Eigen::Vector3f(hi.x(), hi.y(), hi.z()),
                  Eigen::Vector3f(lo.x(), hi.y(), hi.z())});
}

void Mesh::add_yawed_box(float cx, float cy, float sx, float sy, float yaw, float z0, float z1) {
  if (!(sx > 0.f && sy > 0.f && z1 > z0)) return;
  const float c = std::cos(yaw), s = std::sin(yaw);
  std::array<Eigen::Vector3f, 8> v;
  const float hx[4] = {-sx / 2, sx / 2, sx / 2, -sx / 2};
  const float hy[4] = {-sy / 2, -sy / 2, sy / 2, sy / 2};
  for (int i = 0; i < 4; ++i) {
    const float x = cx + c * hx[i] - s * hy[i];
    const float y = cy + s * hx[i] + c * hy[i];
    v[i] = {x, y, z0};
    v[i + 4] = {x, y, z1};
  }
  add_hexahedron(v);
}

Eigen::Vector3f Mesh::normal(std::size_t i) const {
  const auto& t = triangles[i];
  const Eigen::Vector3f n =
      (vertices[t[1]] - vertices[t[0]]).cross(vertices[t[2]] - vertices[t[0]]);
  const float len = n.norm();
  return len > 0.f ? Eigen::Vector3f(n / len) : Eigen::Vector3f::Zero();
}

double Mesh::area() const {
  double a = 0.0;
  for (const auto& t : triangles)
    a += 0.5 * (vertices[t[1]] - vertices[t[0]]).cross(vertices[t[2]] - vertices[t[0]]).norm();
  return a;
}

bool Mesh::valid() const {
  for (const auto& v : vertices)
    if (!v.allFinite()) return false;
  for (const auto& t : triangles)
    for (auto i : t)
      if (i >= vertices.size()) return false;
  return true;
}

}  // namespace storey::tools::sim
