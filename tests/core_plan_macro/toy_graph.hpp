#pragma once
// Toy graphs for the macro-layer unit tests: rectangular rooms filled with a grid of nodes
// (4-neighbour edges inside a room), doors as single extra edges between rooms. Clearance of a
// node = distance to its room's walls (the rectangle's sides).
#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/Core>

#include "core/plan/graph_search.hpp"

namespace storey::test::macro {

struct Room {
  double x0, y0, x1, y1, z = 0;  // walls [m]
};

struct ToyGraph {
  std::vector<Eigen::Vector3d> pos;
  std::vector<int> room_of;
  std::vector<double> clearance;
  std::vector<core::plan::SearchGraph::Edge> edges;

  // Nodes at spacing s starting s/2 inside the walls.
  void add_room(const Room& r, double s, int id) {
    const size_t first = pos.size();
    const int nx = int(std::floor((r.x1 - r.x0) / s)), ny = int(std::floor((r.y1 - r.y0) / s));
    for (int i = 0; i < nx; ++i)
      for (int j = 0; j < ny; ++j) {
        const double x = r.x0 + s * (i + 0.5), y = r.y0 + s * (j + 0.5);
        pos.emplace_back(x, y, r.z);
        room_of.push_back(id);
        clearance.push_back(std::min({x - r.x0, r.x1 - x, y - r.y0, r.y1 - y}));
      }
    for (int i = 0; i < nx; ++i)
      for (int j = 0; j < ny; ++j) {
        const uint32_t u = uint32_t(first + size_t(i * ny + j));
        if (i + 1 < nx) link(u, u + uint32_t(ny));
        if (j + 1 < ny) link(u, u + 1);
      }
  }
  void link(uint32_t a, uint32_t b) { edges.push_back({a, b, (pos[a] - pos[b]).norm()}); }
  uint32_t nearest(const Eigen::Vector3d& p) const {
    uint32_t best = 0;
    for (uint32_t i = 1; i < pos.size(); ++i)
      if ((pos[i] - p).norm() < (pos[best] - p).norm()) best = i;
    return best;
  }
  core::plan::SearchGraph csr() const {
    return core::plan::SearchGraph::from_edges(pos, edges, /*undirected=*/true);
  }
};

}  // namespace storey::test::macro
