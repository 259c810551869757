#include "core/plan/graph_search.hpp"

namespace storey::core::plan {

SearchGraph SearchGraph::from_edges(std::span<const Eigen::Vector3d> positions,
                                    std::span<const Edge> edges, bool undirected, size_t* dropped) {
  SearchGraph g;
  const size_t n = positions.size();
  g.positions_m.assign(positions.begin(), positions.end());
  auto valid = [&](const Edge& e) {
    return e.from < n && e.to < n && !std::isnan(e.weight) && e.weight >= 0;
  };
  std::vector<uint32_t> degree(n + 1, 0);
  size_t bad = 0;
  for (const Edge& e : edges) {
    if (!valid(e)) {
      ++bad;
      continue;
    }
    ++degree[e.from];
    if (undirected) ++degree[e.to];
  }
  g.offsets.assign(n + 1, 0);
  for (size_t u = 0; u < n; ++u) g.offsets[u + 1] = g.offsets[u] + degree[u];
  g.targets.resize(g.offsets[n]);
  g.weights.resize(g.offsets[n]);
  std::vector<uint32_t> fill(g.offsets.begin(), g.offsets.end() - 1);
  for (const Edge& e : edges) {
    if (!valid(e)) continue;
    g.targets[fill[e.from]] = e.to;
    g.weights[fill[e.from]++] = e.weight;
    if (undirected) {
      g.targets[fill[e.to]] = e.from;
      g.weights[fill[e.to]++] = e.weight;
    }
  }
  if (dropped) *dropped = bad;
  return g;
}

}  // namespace storey::core::plan
