#include "core/plan/graph_search.hpp"

#include <gtest/gtest.h>

#include <random>
#include <vector>

namespace storey::core::plan {
namespace {

// A w x h grid (1 m spacing) with 8-connected edges (length-weighted, some scaled up as "rough"),
// a fraction of edges removed at random.
SearchGraph random_grid(int w, int h, std::mt19937& rng, double keep = 0.8) {
  std::vector<Eigen::Vector3d> pos;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) pos.emplace_back(x, y, 0.1 * ((x * 7 + y * 3) % 5));
  std::vector<SearchGraph::Edge> edges;
  std::uniform_real_distribution<double> u(0, 1);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (auto [dx, dy] : {std::pair{1, 0}, {0, 1}, {1, 1}, {1, -1}}) {
        const int nx = x + dx, ny = y + dy;
        if (nx < 0 || ny < 0 || nx >= w || ny >= h || u(rng) > keep) continue;
        const uint32_t a = uint32_t(y * w + x), b = uint32_t(ny * w + nx);
        edges.push_back({a, b, (pos[a] - pos[b]).norm() * (1.0 + u(rng))});
      }
  return SearchGraph::from_edges(pos, edges, true);
}

std::vector<std::vector<double>> floyd(const SearchGraph& g) {
  const size_t n = g.num_nodes();
  std::vector<std::vector<double>> d(n, std::vector<double>(n, kUnreachable));
  for (uint32_t u = 0; u < n; ++u) {
    d[u][u] = 0;
    g.for_each_edge(u, [&](uint32_t v, double w, uint32_t) { d[u][v] = std::min(d[u][v], w); });
  }
  for (size_t k = 0; k < n; ++k)
    for (size_t i = 0; i < n; ++i)
      for (size_t j = 0; j < n; ++j) d[i][j] = std::min(d[i][j], d[i][k] + d[k][j]);
  return d;
}

TEST(GraphSearch, AStarAndDijkstraMatchFloydWarshall) {
  std::mt19937 rng(1);
  const SearchGraph g = random_grid(9, 7, rng);
  const auto d = floyd(g);
  GraphSearch s;
  const uint32_t n = uint32_t(g.num_nodes());
  for (uint32_t a = 0; a < n; a += 5) {
    std::vector<uint32_t> all(n);
    for (uint32_t i = 0; i < n; ++i) all[i] = i;
    std::vector<double> row(n);
    s.costs_from(g, a, all, row);
    for (uint32_t b = 0; b < n; ++b) {
      EXPECT_NEAR(row[b], d[a][b], 1e-9);
      const PathResult r = s.astar(g, a, b);
      EXPECT_EQ(r.found, d[a][b] < kUnreachable);
      if (!r.found) continue;
      EXPECT_NEAR(r.cost, d[a][b], 1e-9);
      ASSERT_FALSE(r.nodes.empty());
      EXPECT_EQ(r.nodes.front(), a);
      EXPECT_EQ(r.nodes.back(), b);
    }
  }
}

TEST(GraphSearch, BoundedDijkstraSettlesExactlyTheBall) {
  std::mt19937 rng(2);
  const SearchGraph g = random_grid(10, 10, rng);
  const auto d = floyd(g);
  GraphSearch s;
  const uint32_t src = 45;
  for (double r : {0.0, 1.5, 3.0, 6.0}) {
    const auto settled = s.dijkstra(g, std::span<const uint32_t>(&src, 1), r);
    size_t expected = 0;
    for (size_t v = 0; v < g.num_nodes(); ++v) expected += d[src][v] <= r;
    EXPECT_EQ(settled.size(), expected) << r;
    double prev = 0;
    for (const Settled& st : settled) {
      EXPECT_NEAR(st.dist, d[src][st.node], 1e-9);
      EXPECT_GE(st.dist, prev);  // settled in order of distance
      prev = st.dist;
    }
    for (size_t v = 0; v < g.num_nodes(); ++v) {  // nothing beyond the radius reports a distance
      if (d[src][v] > r) {
        EXPECT_EQ(s.dist(uint32_t(v)), kUnreachable);
      }
    }
  }
}

TEST(GraphSearch, EdgeFilterAndTwoStage) {
  // 0 - 1 - 2 - 3 real chain (long), 0 - 4 - 3 through a hypothetical node 4 (short), and a
  // hypothetical-only island 5 reachable only from 3 via a hypothetical edge.
  std::vector<Eigen::Vector3d> pos{{0, 0, 0}, {1, 1, 0},   {2, 1, 0},
                                   {3, 0, 0}, {1.5, 0, 0}, {4, 0, 0}};
  std::vector<SearchGraph::Edge> e{{0, 1, 1.5}, {1, 2, 1.0}, {2, 3, 1.5},
                                   {0, 4, 1.5}, {4, 3, 1.5}, {3, 5, 1.0}};
  const SearchGraph g = SearchGraph::from_edges(pos, e, true);
  const std::vector<bool> real_node{true, true, true, true, false, false};
  auto is_real = [&](uint32_t, uint32_t a, uint32_t b) { return real_node[a] && real_node[b]; };
  GraphSearch s;
  const TwoStageResult r1 = s.two_stage_astar(g, 0, 3, is_real);
  ASSERT_TRUE(r1.found);
  EXPECT_FALSE(r1.used_hybrid);
  EXPECT_EQ(r1.nodes, (std::vector<uint32_t>{0, 1, 2, 3}));
  EXPECT_DOUBLE_EQ(r1.cost, 4.0);
  // Unfiltered A* takes the shorter hypothetical route.
  EXPECT_EQ(s.astar(g, 0, 3).nodes, (std::vector<uint32_t>{0, 4, 3}));
  // Into hypothetical space: stage 2, and execution follows only the real prefix.
  const TwoStageResult r2 = s.two_stage_astar(g, 0, 5, is_real);
  ASSERT_TRUE(r2.found);
  EXPECT_TRUE(r2.used_hybrid);
  EXPECT_EQ(r2.nodes, (std::vector<uint32_t>{0, 4, 3, 5}));
  EXPECT_EQ(real_prefix_length(std::span<const uint32_t>(r2.nodes),
                               [&](uint32_t u) { return bool(real_node[u]); }),
            1u);
  // Bad edges are dropped and counted.
  size_t dropped = 0;
  std::vector<SearchGraph::Edge> bad{{0, 9, 1.0}, {0, 1, -1.0}, {0, 1, std::nan("")}, {0, 1, 1}};
  const SearchGraph g2 = SearchGraph::from_edges(pos, bad, false, &dropped);
  EXPECT_EQ(dropped, 3u);
  EXPECT_EQ(g2.num_edges(), 1u);
  EXPECT_FALSE(s.astar(g2, 0, 99).found);  // out-of-range goal: not found, no crash
}

TEST(GraphSearch, ReusedAcrossGraphSizes) {
  std::mt19937 rng(3);
  GraphSearch s;
  for (int k = 0; k < 5; ++k) {
    const SearchGraph g = random_grid(3 + 4 * (k % 3), 4, rng, 1.0);
    const uint32_t last = uint32_t(g.num_nodes() - 1);
    const PathResult r = s.astar(g, 0, last);
    ASSERT_TRUE(r.found);
    EXPECT_GE(r.cost, (g.position(0) - g.position(last)).norm());
  }
}

}  // namespace
}  // namespace storey::core::plan
