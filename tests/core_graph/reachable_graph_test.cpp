// G_real (paper Sec. III-B): multi-floor connectivity, states, pruning, determinism.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <queue>
#include <set>

#include <gtest/gtest.h>

#include "core/graph/map_change_detector.hpp"
#include "core/graph/reachable_graph.hpp"
#include "tests/core_graph/graph_world.hpp"

using namespace storey::core::graph;
using Eigen::Vector3f;
using storey::test::graph::Harness;
using storey::test::graph::World;

namespace {

constexpr float kRise = 3.0f / 18.f, kTread = 0.28f;

// Two storeys 3 m apart (slab tops 0.03 and 3.03 m) joined by a straight flight of 18 steps of
// 0.167 m under a stairwell opening (x in [-2, 3.04], y in [2.6, 4]).
World two_floor_building() {
  World w;
  w.add({-6, -4, -0.3f}, {6, 4, 0.03f});     // ground slab
  w.add({-6, -4, 2.83f}, {6, 2.6f, 3.03f});  // upper slab with the stairwell hole
  w.add({-6, 2.6f, 2.83f}, {-2, 4, 3.03f});
  w.add({3.04f, 2.6f, 2.83f}, {6, 4, 3.03f});
  w.stairs(-2.0f, 2.7f, 3.9f, 0.03f, 18, kRise, kTread);
  w.add({-6.2f, -4.2f, -0.3f}, {-6, 4.2f, 6});  // outer walls
  w.add({6, -4.2f, -0.3f}, {6.2f, 4.2f, 6});
  w.add({-6, -4.2f, -0.3f}, {6, -4, 6});
  w.add({-6, 4, -0.3f}, {6, 4.2f, 6});
  w.add({-6, 2.5f, 0.03f}, {-2.5f, 2.6f, 2.83f});  // wall beside the stairs, ground floor
  return w;
}

// Top of the highest box within 0.15 m of (x, y) whose top is at most z_max: the analytic
// support height, tolerant to the map's discretisation at box borders (0.1 m voxels, and the
// graph may take a support from the neighbour column, SupportQuery::support_dilated).
float support_height(const World& w, float x, float y, float z_max) {
  float best = -1e9f;
  const float t = 0.15f;
  for (const auto& b : w.boxes)
    if (x >= b.lo.x() - t && x <= b.hi.x() + t && y >= b.lo.y() - t && y <= b.hi.y() + t &&
        b.hi.z() <= z_max)
      best = std::max(best, b.hi.z());
  return best;
}

void explore_two_floors(Harness& h, const World& w) {
  std::vector<std::pair<Vector3f, Vector3f>> path;  // (sensor, foot)
  auto at = [&](float x, float y, float ground) {
    path.push_back({Vector3f(x, y, ground + 0.52f), Vector3f(x, y, ground)});
  };
  for (float x : {-4.f, -1.f, 2.f, 4.f}) at(x, 0, 0.03f);
  at(-3, 3.3f, 0.03f);
  for (int i = 0; i < 18; i += 3) at(-2.0f + (i + 0.5f) * kTread, 3.3f, 0.03f + (i + 1) * kRise);
  for (float x : {4.5f, 4.f, 0.f, -4.f}) at(x, x == 4.5f ? 3.3f : 0.f, 3.03f);
  uint32_t seed = 1;
  for (const auto& [s, f] : path) h.observe(w, s, f, 60000, seed++);
}

// Node ids reachable from `from` over edges (BFS), with parents.
std::map<NodeId, NodeId> bfs_tree(const ReachableGraph& g, NodeId from) {
  std::map<NodeId, NodeId> parent{{from, from}};
  std::queue<NodeId> q;
  q.push(from);
  while (!q.empty()) {
    const NodeId u = q.front();
    q.pop();
    const GraphNode& n = g.node(u);
    for (int k = 0; k < n.degree; ++k) {
      const NodeId v = g.edge(n.edges[k]).other(u);
      if (parent.emplace(v, u).second) q.push(v);
    }
  }
  return parent;
}

void dump(const ReachableGraph& g) {
  if (!getenv("STOREY_DEBUG")) return;
  for (NodeId i = 0; i < g.node_capacity(); ++i) {
    const GraphNode& n = g.node(i);
    if (n.alive)
      printf("node %u %.2f %.2f %.2f s%d deg %d\n", i, n.p_m.x(), n.p_m.y(), n.p_m.z(),
             int(n.state), n.degree);
  }
}

}  // namespace

TEST(ReachableGraph, ConnectsFloorsThroughStairsNeverThroughSlab) {
  const World w = two_floor_building();
  Harness h;
  explore_two_floors(h, w);
  const ReachableGraph& g = h.graph;
  dump(g);
  ASSERT_GT(g.node_count(), 60u);
  int lower = 0, upper = 0;
  NodeId a_low = kNoId, a_up = kNoId;
  for (NodeId i = 0; i < g.node_capacity(); ++i) {
    const GraphNode& n = g.node(i);
    if (!n.alive) continue;
    // Every node stands on a real surface (the analytic support under it).
    EXPECT_NEAR(n.p_m.z(), support_height(w, n.p_m.x(), n.p_m.y(), n.p_m.z() + 0.1f), 0.1f)
        << "node " << i << " at " << n.p_m.transpose() << " state " << int(n.state) << " degree "
        << int(n.degree) << " first neighbour "
        << (n.degree ? g.node(g.edge(n.edges[0]).other(i)).p_m.transpose() : n.p_m.transpose());
    if (std::abs(n.p_m.z() - 0.03f) < 0.05f && n.p_m.y() < 2.4f) {
      ++lower;
      if (a_low == kNoId) a_low = i;
    }
    if (std::abs(n.p_m.z() - 3.03f) < 0.05f && n.p_m.y() < 2.4f) {
      ++upper;
      if (a_up == kNoId) a_up = i;
    }
  }
  EXPECT_GT(lower, 25);
  EXPECT_GT(upper, 25);
  // Every confirmed edge is a walk over the analytic surface in steps no higher than a stair
  // step (tentative ones may cross up to max_gap_m of unknown ground by design); no edge of any
  // state climbs more than half a metre except on the flight of stairs.
  for (EdgeId e = 0; e < g.edge_capacity(); ++e) {
    const GraphEdge& ge = g.edge(e);
    if (!ge.alive) continue;
    const Vector3f a = g.node(ge.a).p_m, b = g.node(ge.b).p_m;
    if (std::abs(a.z() - b.z()) > 0.5f) {  // climbing: only on or at the ends of the flight
      const Vector3f m = 0.5f * (a + b);
      EXPECT_TRUE(m.x() > -2.6f && m.x() < 3.7f && m.y() > 2.5f)
          << "edge " << e << " climbs off the stairs: " << a.transpose() << " -> " << b.transpose();
    }
    if (ge.state != ElementState::kConfirmed) continue;
    float z = a.z();
    for (int k = 1; k <= 40; ++k) {
      const Vector3f p = a + (b - a) * (float(k) / 40.f);
      const float s = support_height(w, p.x(), p.y(), z + 0.2f);
      EXPECT_LE(std::abs(s - z), 0.2f) << "edge " << e << " " << a.transpose() << " -> "
                                       << b.transpose() << " jumps at " << p.transpose();
      z = s;
    }
  }
  // The floors are connected, and only through the flight of stairs.
  ASSERT_NE(a_low, kNoId);
  ASSERT_NE(a_up, kNoId);
  const auto tree = bfs_tree(g, a_low);
  ASSERT_TRUE(tree.count(a_up)) << "upper floor not connected to the ground floor";
  bool via_stairs = false;
  for (NodeId v = a_up; v != a_low; v = tree.at(v)) {
    const Vector3f p = g.node(v).p_m;
    if (p.z() > 0.5f && p.z() < 2.6f) {
      via_stairs = true;
      EXPECT_GT(p.x(), -2.1f);
      EXPECT_LT(p.x(), 3.1f);
      EXPECT_GT(p.y(), 2.6f);
    }
  }
  EXPECT_TRUE(via_stairs);
}

TEST(ReachableGraph, SameSeedSameGraph) {
  const World w = two_floor_building();
  auto run = [&](uint64_t seed) {
    Harness h({}, seed);
    for (int i = 0; i < 3; ++i)
      h.observe(w, Vector3f(-4 + 3 * i, 0, 0.55f), Vector3f(-4 + 3 * i, 0, 0.03f), 40000, i + 1);
    std::vector<float> sig;
    for (NodeId n = 0; n < h.graph.node_capacity(); ++n) {
      const GraphNode& gn = h.graph.node(n);
      sig.push_back(gn.alive ? gn.p_m.x() + 100 * gn.p_m.y() + 1e4f * gn.p_m.z() : -1.f);
      sig.push_back(float(gn.degree));
    }
    return sig;
  };
  const auto a = run(7), b = run(7), c = run(8);
  EXPECT_EQ(a, b);
  EXPECT_NE(a, c);
}

namespace {

// A walled corridor 2 m wide along x from -2 to 14 m (floor top at z = 0).
World corridor() {
  World w;
  w.add({-2.2f, -1.2f, -0.3f}, {14.2f, 1.2f, 0.0f});
  w.add({-2.2f, -1.2f, 0.0f}, {14.2f, -1.0f, 2.5f});
  w.add({-2.2f, 1.0f, 0.0f}, {14.2f, 1.2f, 2.5f});
  w.add({-2.2f, -1.0f, 0.0f}, {-2.0f, 1.0f, 2.5f});
  w.add({14.0f, -1.0f, 0.0f}, {14.2f, 1.0f, 2.5f});
  return w;
}

struct GapScenario {
  World w = corridor();
  Harness h;
  explicit GapScenario(const GraphOptions& o = {}) : h(o, 3) {
    const Vector3f foot(0, 0, 0);
    // Near part dense (robot's own view), far part dense from a scan far ahead (C_reach cannot
    // get there), the middle only sparsely (a few returns per voxel: S_unobs, holes).
    h.observe(w, Vector3f(0, 0, 0.55f), foot, 200000, 11, 3.0f);
    h.observe(w, Vector3f(11, 0, 0.55f), foot, 200000, 12, 3.0f);
    h.observe(w, Vector3f(6, 0, 0.55f), foot, 20000, 13, 4.0f);
  }
  int count(float x0, float x1, ElementState s) const {
    int n = 0;
    for (NodeId i = 0; i < h.graph.node_capacity(); ++i) {
      const GraphNode& gn = h.graph.node(i);
      n += gn.alive && gn.p_m.x() >= x0 && gn.p_m.x() < x1 && gn.state == s;
    }
    return n;
  }
  int count(float x0, float x1) const {
    return count(x0, x1, ElementState::kConfirmed) + count(x0, x1, ElementState::kTentative);
  }
};

}  // namespace

TEST(ReachableGraph, TentativeBridgesSparseGapAndIsPromoted) {
  GapScenario s;
  dump(s.h.graph);
  EXPECT_GT(s.count(-2, 3.5f, ElementState::kConfirmed), 8);
  EXPECT_GT(s.count(4.5f, 7.5f, ElementState::kTentative), 0) << "no tentative node in the gap";
  EXPECT_GT(s.count(9.0f, 14.0f), 5) << "the graph did not bridge the gap";
  // Remember the tentative nodes of the gap.
  std::vector<NodeId> gap;
  for (NodeId i = 0; i < s.h.graph.node_capacity(); ++i) {
    const GraphNode& n = s.h.graph.node(i);
    if (n.alive && n.state == ElementState::kTentative && n.p_m.x() > 4.5f && n.p_m.x() < 7.5f)
      gap.push_back(i);
  }
  // Observe the gap densely: C_reach now covers it; the same nodes are promoted.
  s.h.observe(s.w, Vector3f(6, 0, 0.55f), Vector3f(0, 0, 0), 60000, 14, 4.0f);
  s.h.observe(s.w, Vector3f(3, 0, 0.55f), Vector3f(0, 0, 0), 60000, 15, 4.0f);
  s.h.observe(s.w, Vector3f(9, 0, 0.55f), Vector3f(0, 0, 0), 60000, 16, 4.0f);
  int promoted = 0;
  for (NodeId i : gap)
    promoted += s.h.graph.node(i).alive && s.h.graph.node(i).state == ElementState::kConfirmed;
  EXPECT_GE(promoted * 10, int(gap.size()) * 7) << promoted << " of " << gap.size();
  EXPECT_GE(s.count(-2, 14, ElementState::kConfirmed) * 10, s.count(-2, 14) * 9);
  EXPECT_GT(s.count(9.0f, 14.0f, ElementState::kConfirmed), 5);
}

TEST(ReachableGraph, WithoutTentativeTheGraphStaysInReach) {
  GraphOptions o;
  o.use_tentative = false;
  GapScenario s(o);
  EXPECT_EQ(s.count(-3, 15, ElementState::kTentative), 0);
  EXPECT_GT(s.count(-2, 3.5f, ElementState::kConfirmed), 8);
  EXPECT_EQ(s.count(4.5f, 14.0f), 0) << "confirmed-only graph left C_reach";
  const auto v = s.h.map.view();
  for (NodeId i = 0; i < s.h.graph.node_capacity(); ++i)
    if (s.h.graph.node(i).alive) {
      EXPECT_TRUE(v.is_reachable(s.h.graph.node(i).key)) << i;
    }
}

TEST(ReachableGraph, ObstacleInGapPrunesElementsThere) {
  GapScenario s;
  ASSERT_GT(s.count(9.0f, 14.0f), 5);
  // A 0.6 m box appears right on a tentative node of the gap (the corridor stays passable).
  NodeId victim = kNoId;
  for (NodeId i = 0; i < s.h.graph.node_capacity() && victim == kNoId; ++i) {
    const GraphNode& n = s.h.graph.node(i);
    if (n.alive && n.state == ElementState::kTentative && n.p_m.x() > 4.5f && n.p_m.x() < 7.5f &&
        std::abs(n.p_m.y()) < 0.45f)
      victim = i;
  }
  ASSERT_NE(victim, kNoId);
  const Vector3f c = s.h.graph.node(victim).p_m;
  const Vector3f lo(c.x() - 0.3f, c.y() - 0.3f, 0.0f), hi(c.x() + 0.3f, c.y() + 0.3f, 0.5f);
  s.w.add(lo, hi);
  s.h.observe(s.w, Vector3f(c.x() - 1.5f, 0, 0.55f), Vector3f(0, 0, 0), 60000, 21, 4.0f);
  const uint32_t pruned_first = s.h.last.nodes_pruned + s.h.last.edges_pruned;
  s.h.observe(s.w, Vector3f(c.x() + 1.5f, 0, 0.55f), Vector3f(0, 0, 0), 60000, 22, 4.0f);
  const ReachableGraph& g = s.h.graph;
  EXPECT_FALSE(g.node(victim).alive && (g.node(victim).p_m - c).norm() < 0.01f);
  // Pruned in the cycle of either observation (whichever first saw the box's faces).
  EXPECT_GT(pruned_first + s.h.last.nodes_pruned + s.h.last.edges_pruned, 0u);
  auto in_box = [&](const Vector3f& p, float shrink) {
    return p.x() > lo.x() + shrink && p.x() < hi.x() - shrink && p.y() > lo.y() + shrink &&
           p.y() < hi.y() - shrink;
  };
  for (NodeId i = 0; i < g.node_capacity(); ++i)
    if (g.node(i).alive) {
      EXPECT_FALSE(in_box(g.node(i).p_m, -0.1f)) << "node " << i;
    }
  for (EdgeId e = 0; e < g.edge_capacity(); ++e) {
    const GraphEdge& ge = g.edge(e);
    if (!ge.alive) continue;
    for (int k = 0; k <= 20; ++k) {
      const Vector3f p = g.node(ge.a).p_m + (g.node(ge.b).p_m - g.node(ge.a).p_m) * (k / 20.f);
      EXPECT_FALSE(in_box(p, 0.05f)) << "edge " << e << " crosses the obstacle";
    }
  }
  // Whatever survived is connected to the robot (components cut off by the pruning are gone).
  ASSERT_NE(g.root(), kNoId);
  const auto tree = bfs_tree(g, g.root());
  EXPECT_EQ(tree.size(), g.node_count());
}

TEST(ReachableGraph, CuttingTheCorridorRemovesTheFarComponent) {
  GapScenario s;
  s.h.observe(s.w, Vector3f(6, 0, 0.55f), Vector3f(0, 0, 0), 60000, 14, 4.0f);
  ASSERT_GT(s.count(9.0f, 14.0f), 5);
  const size_t before = s.h.graph.node_count();
  s.w.add({5.0f, -1.0f, 0.0f}, {5.2f, 1.0f, 2.5f});  // a wall closes the corridor
  s.h.observe(s.w, Vector3f(4, 0, 0.55f), Vector3f(0, 0, 0), 60000, 31, 4.0f);
  EXPECT_EQ(s.count(5.2f, 15.0f), 0) << "cut-off component survived";
  EXPECT_GT(s.count(-2.0f, 4.5f), 8);
  EXPECT_LT(s.h.graph.node_count(), before);
  EXPECT_GT(s.h.last.disconnected, 0u);
}

// A cut that leaves the robot in the smaller part is held for prune_persistence_updates
// (a transient loss of the link near the robot must not wipe the explored graph), then pruned.
TEST(ReachableGraph, CutLeavingTheRobotInTheSmallerPartWaitsBeforePruning) {
  GraphOptions o;
  o.prune_persistence_updates = 12;
  GapScenario s(o);
  s.h.observe(s.w, Vector3f(6, 0, 0.55f), Vector3f(0, 0, 0), 60000, 14, 4.0f);
  const int far_before = s.count(5.2f, 15.0f);
  ASSERT_GT(far_before, s.count(-2.0f, 4.5f)) << "the scenario needs the far part larger";
  s.w.add({5.0f, -1.0f, 0.0f}, {5.2f, 1.0f, 2.5f});
  s.h.settle_cycles = 0;
  s.h.observe(s.w, Vector3f(4, 0, 0.55f), Vector3f(0, 0, 0), 60000, 31, 4.0f);
  int deferred = 0;
  for (int i = 0; i < 200 && !s.h.graph.idle() && s.count(5.2f, 15.0f) > 0; ++i) {
    const auto st = s.h.graph.update(s.h.map.view(), s.h.foot, {}, s.h.rng);
    deferred += st.prune_deferred;
    if (st.prune_deferred) {
      EXPECT_GT(s.count(5.2f, 15.0f), 0);
    }
  }
  EXPECT_GT(deferred, 0) << "the cut was pruned at once";
  EXPECT_LE(deferred, o.prune_persistence_updates);
  EXPECT_EQ(s.count(5.2f, 15.0f), 0) << "a lasting cut must still be pruned";
  EXPECT_GT(s.count(-2.0f, 4.5f), 8);
}

TEST(MapChangeDetector, ReportsWhereTheMapChangedAndWhatWasRemoved) {
  World w = corridor();
  storey::core::map::TraversabilityMap m;
  MapChangeDetector d;
  std::vector<Aabb> changed, opened;
  auto scan = [&](uint32_t seed) {
    const Vector3f o(3, 0, 0.55f);
    const auto pts = storey::test::graph::scan(w, o, 100000, seed, 5.0f);
    m.insert_scan(o, pts);
    m.update_traversability();
    m.update_reachable(Vector3f(3, 0, 0));
    const Aabb box = scan_bounds(o, pts);
    changed.clear();
    opened.clear();
    return d.detect(m.view(), std::span(&box, 1), changed, &opened);
  };
  EXPECT_GT(scan(1), 0u);  // first sight: everything is new
  // (Re-observing a static scene still flips some blocks: surface voxels alternate between
  // free and occupied under grazing rays; PERFORMANCE.md gives the per-cycle counts.)
  for (uint32_t s = 2; s < 7; ++s) scan(s);
  // A box appears at x = 5: the change is reported there, and nothing was removed.
  w.add({4.8f, -0.2f, 0.0f}, {5.2f, 0.2f, 0.8f});
  scan(7);
  bool covers = false;
  for (const Aabb& b : changed) covers |= b.inflated(0.2f).contains(Vector3f(5, 0, 0.4f));
  EXPECT_TRUE(covers) << "the new box is not inside a changed region";
  w.boxes.pop_back();  // ... and leaves again: its blocks lose occupied voxels.
  bool opened_there = false;
  for (uint32_t s = 9; s < 13 && !opened_there; ++s) {
    scan(s);
    for (const Aabb& b : opened) opened_there |= b.inflated(0.2f).contains(Vector3f(5, 0, 0.4f));
  }
  EXPECT_TRUE(opened_there) << "the removal is not reported as an opening";
}

// GraphOptions::root_off_graph: a robot standing half a step or more above the nearest node and
// away from it (a landing reached by a blind climb) gets a node of its own on the support under
// its feet; without the option the nearest node is its node.
TEST(ReachableGraph, RootOffGraphIsANewNodeUnderTheFeet) {
  World w;
  w.add({-4, -2, -0.3f}, {0, 2, 0.0f});  // floor
  w.add({0, -2, -0.3f}, {3, 2, 0.15f});  // a platform 0.15 m up, not seen from the floor
  for (bool off_graph : {false, true}) {
    GraphOptions o;
    o.root_radius_m = 2.0;
    o.root_off_graph = off_graph;
    Harness h(o);
    h.observe(w, {-1.5f, 0, 0.5f}, {-1.5f, 0, 0}, 60000, 1, 1.2f);
    ASSERT_NE(h.graph.root(), kNoId);
    for (NodeId i = 0; i < h.graph.node_capacity(); ++i) {
      if (h.graph.node(i).alive) {
        ASSERT_LT(h.graph.node(i).p_m.z(), 0.05f);
      }
    }
    h.settle_cycles = 0;  // the root is attached before any expansion in the update
    h.observe(w, {0.3f, 0, 0.65f}, {0.3f, 0, 0.15f}, 60000, 2, 3.0f);
    ASSERT_NE(h.graph.root(), kNoId);
    const Vector3f r = h.graph.node(h.graph.root()).p_m;
    if (off_graph) {
      EXPECT_NEAR(r.z(), 0.15f, 0.06f) << r.transpose();
    } else {
      EXPECT_LT(r.z(), 0.05f) << r.transpose();
    }
  }
}

namespace {
// The corridor, graph grown over its whole length, then narrowed at x = 5 to an opening
// opening_m wide (observed from the robot's side).
struct NarrowedCorridor {
  World w = corridor();
  Harness h;
  explicit NarrowedCorridor(const GraphOptions& o) : h(o, 3) {
    const Vector3f foot(0, 0, 0);
    for (float x : {0.f, 3.f, 7.f, 10.f, 12.f})
      h.observe(w, Vector3f(x, 0, 0.55f), foot, 100000, 11 + int(x), 5.0f);
  }
  void narrow(float opening_m) {
    w.add({5.0f, -1.0f, 0.0f}, {5.2f, -opening_m / 2, 2.5f});
    w.add({5.0f, opening_m / 2, 0.0f}, {5.2f, 1.0f, 2.5f});
    for (int r = 0; r < 3; ++r)
      h.observe(w, Vector3f(3.5f, 0, 0.55f), h.foot, 100000, 40 + r, 5.0f);
  }
  int far(ElementState s) const {
    int n = 0;
    for (NodeId i = 0; i < h.graph.node_capacity(); ++i) {
      const GraphNode& g = h.graph.node(i);
      n += g.alive && g.p_m.x() > 5.3f && g.state == s;
    }
    return n;
  }
};
}  // namespace

// GraphOptions::keep_reachable_cut: narrowing the corridor to a 0.7 m opening removes the nodes
// there (the graph is cut) but C_reach, grown over the map's voxels with R_col, still passes it.
// The far part, every node still in C_reach, is kept and re-linked; without the option it is
// pruned (Maze's ramp lost the ground floor's graph that way).
TEST(ReachableGraph, ACutOfTheGraphButNotOfCReachKeepsTheFarPart) {
  GraphOptions o;
  o.keep_reachable_cut = true;
  NarrowedCorridor s(o);
  const int before = s.far(ElementState::kConfirmed);
  ASSERT_GT(before, 15);
  s.narrow(0.7f);
  EXPECT_GE(s.far(ElementState::kConfirmed), before - 3);
  // Kept, and linked to the robot again by expansion through the opening.
  ASSERT_NE(s.h.graph.root(), kNoId);
  EXPECT_EQ(bfs_tree(s.h.graph, s.h.graph.root()).size(), s.h.graph.node_count());

  // Without the option the same cut (same seeds) prunes the far part, and it does not regrow.
  NarrowedCorridor pruned{GraphOptions{}};
  pruned.narrow(0.7f);
  EXPECT_EQ(pruned.far(ElementState::kConfirmed) + pruned.far(ElementState::kTentative), 0);
}

// ... but a wall across the corridor cuts C_reach too: the far part goes, option or not.
TEST(ReachableGraph, KeepReachableCutStillPrunesAClosedCorridor) {
  GraphOptions o;
  o.keep_reachable_cut = true;
  GapScenario s(o);
  s.h.observe(s.w, Vector3f(6, 0, 0.55f), Vector3f(0, 0, 0), 60000, 14, 4.0f);
  ASSERT_GT(s.count(9.0f, 14.0f), 5);
  s.w.add({5.0f, -1.0f, 0.0f}, {5.2f, 1.0f, 2.5f});
  s.h.observe(s.w, Vector3f(4, 0, 0.55f), Vector3f(0, 0, 0), 60000, 31, 4.0f);
  EXPECT_EQ(s.count(5.2f, 15.0f), 0) << "cut-off component survived";
  EXPECT_GT(s.count(-2.0f, 4.5f), 8);
}

// GraphOptions::relink_cuts: the same cut kept by keep_reachable_cut, with expansion slowed to one
// node per update (in the office, seed 3, no expansion re-linked a room cut off at its 0.9 m door
// and the run ended "complete" at 85.5 s with 48.6 % seen): the parts stay two components without
// the option, and are one again within the observation's updates with it.
TEST(ReachableGraph, RelinkCutsJoinsAKeptCutThatExpansionLeft) {
  for (const bool relink : {false, true}) {
    GraphOptions o;
    o.keep_reachable_cut = true;
    o.relink_cuts = relink;
    o.max_expansions_per_update = 1;
    NarrowedCorridor s(o);
    s.narrow(0.8f);
    ASSERT_NE(s.h.graph.root(), kNoId);
    ASSERT_GT(s.far(ElementState::kConfirmed), 15);  // the far part is kept either way
    const size_t linked = bfs_tree(s.h.graph, s.h.graph.root()).size();
    if (relink) {
      EXPECT_EQ(linked, s.h.graph.node_count());
    } else {
      EXPECT_LT(2 * linked, s.h.graph.node_count());  // measured 20 of 52
    }
  }
}
