// Topological frontiers, clustering, viewpoints and export (paper Sec. III-C).
#include <set>
#include <string>

#include <gtest/gtest.h>

#include "core/graph/frontier_clusters.hpp"
#include "core/graph/graph_export.hpp"
#include "core/graph/support_query.hpp"
#include "core/graph/topological_frontiers.hpp"
#include "core/graph/viewpoint_generator.hpp"
#include "tests/core_graph/graph_world.hpp"

using namespace storey::core::graph;
using Eigen::Vector3f;
using storey::test::graph::Harness;
using storey::test::graph::World;

namespace {

// A 12 x 8 m room (floor top z = 0) split by a wall along x = 0 from the south wall up to
// y = 2.5 m; the two halves meet through a 1.5 m opening in the north.
World split_room() {
  World w;
  w.add({-6.2f, -4.2f, -0.3f}, {6.2f, 4.2f, 0.0f});
  w.add({-6.2f, -4.2f, 0.0f}, {6.2f, -4.0f, 2.5f});
  w.add({-6.2f, 4.0f, 0.0f}, {6.2f, 4.2f, 2.5f});
  w.add({-6.2f, -4.0f, 0.0f}, {-6.0f, 4.0f, 2.5f});
  w.add({6.0f, -4.0f, 0.0f}, {6.2f, 4.0f, 2.5f});
  w.add({-0.1f, -4.0f, 0.0f}, {0.1f, 2.5f, 2.5f});
  return w;
}

// Range-limited scans on both sides: the south strip and the far east / west ends stay unknown.
void observe_split_room(Harness& h, const World& w) {
  const Vector3f foot(-2, 0, 0);
  h.observe(w, Vector3f(-2, 0, 0.55f), foot, 150000, 1, 3.5f);
  h.observe(w, Vector3f(-1, 3.2f, 0.55f), foot, 150000, 2, 3.5f);
  h.observe(w, Vector3f(1, 3.2f, 0.55f), foot, 150000, 3, 3.5f);
  h.observe(w, Vector3f(2, 0, 0.55f), foot, 150000, 4, 3.5f);
}

std::set<NodeId> flagged(const ReachableGraph& g, bool GraphNode::*flag) {
  std::set<NodeId> out;
  for (NodeId i = 0; i < g.node_capacity(); ++i)
    if (g.node(i).alive && g.node(i).*flag) out.insert(i);
  return out;
}

}  // namespace

TEST(TopologicalFrontiers, WallKeepsFrontierGroupsInSeparateClusters) {
  const World w = split_room();
  GraphOptions o;
  o.cluster_capacity = 1000;  // only connectivity may split the clusters
  Harness h(o);
  observe_split_room(h, w);
  const ReachableGraph& g = h.graph;
  ASSERT_GT(g.node_count(), 40u);
  // Both sides have frontiers, and some are closer across the wall than a Euclidean cluster
  // radius would tolerate.
  float closest = 1e9f;
  int west = 0, east = 0;
  for (NodeId a = 0; a < g.node_capacity(); ++a) {
    if (!g.node(a).alive || !g.node(a).frontier() || g.node(a).p_m.y() > 2.0f) continue;
    west += g.node(a).p_m.x() < 0;
    east += g.node(a).p_m.x() > 0;
    for (NodeId b = 0; b < g.node_capacity(); ++b)
      if (g.node(b).alive && g.node(b).frontier() && g.node(b).p_m.y() < 2.0f &&
          (g.node(a).p_m.x() < 0) != (g.node(b).p_m.x() < 0))
        closest = std::min(closest, (g.node(a).p_m - g.node(b).p_m).norm());
  }
  ASSERT_GT(west, 0);
  ASSERT_GT(east, 0);
  EXPECT_LT(closest, 1.6f) << "scenario: frontiers across the wall are not close";
  FrontierClusters fc(o);
  const auto& clusters = fc.update(h.graph);
  ASSERT_GE(clusters.size(), 2u);
  for (const FrontierCluster& c : clusters) {
    // A cluster may span both halves only through the northern opening (y > 2.5).
    bool w_south = false, e_south = false;
    for (NodeId n : c.nodes) {
      const Vector3f p = g.node(n).p_m;
      EXPECT_EQ(g.node(n).cluster, c.id);
      EXPECT_TRUE(g.node(n).frontier());
      w_south |= p.x() < 0 && p.y() < 1.0f;
      e_south |= p.x() > 0 && p.y() < 1.0f;
    }
    if (w_south && e_south) {
      // Then it must be connected through the north: it contains nodes beyond the wall's end.
      bool north = false;
      for (NodeId n : c.nodes) north |= g.node(n).p_m.y() > 2.5f;
      EXPECT_TRUE(north) << "cluster " << c.id << " merged across the wall";
    }
  }
  // Capacity.
  GraphOptions small = o;
  small.cluster_capacity = 3;
  FrontierClusters fc3(small);
  size_t members = 0;
  for (const FrontierCluster& c : fc3.update(h.graph)) {
    EXPECT_LE(c.nodes.size(), 3u);
    members += c.nodes.size();
  }
  EXPECT_EQ(
      members, flagged(g, &GraphNode::c_sur).size() + flagged(g, &GraphNode::c_exp).size() - [&] {
        size_t both = 0;
        for (NodeId i : flagged(g, &GraphNode::c_sur)) both += g.node(i).c_exp;
        return both;
      }());
}

// explain() (the run record's diagnostics) casts the probes evaluate() casts: as many open as
// open_dirs, and each open probe names unknown space the map really holds (a run into it, or just
// over an obstacle) within a probe's length; probes along edges are not cast.
TEST(TopologicalFrontiers, ExplainNamesTheUnknownThatOpensEachProbe) {
  const World w = split_room();
  GraphOptions o;
  Harness h(o);
  observe_split_room(h, w);
  const ReachableGraph& g = h.graph;
  TopologicalFrontiers tf(o);
  const float vs = float(h.map.view().voxel_size_m());
  int checked = 0;
  for (NodeId i = 0; i < g.node_capacity(); ++i) {
    const GraphNode& n = g.node(i);
    if (!n.alive || !n.c_exp) continue;
    const auto probes = tf.explain(g, h.map.view(), i);
    ASSERT_EQ(probes.size(), size_t(o.probes));
    int open = 0;
    for (const ProbeExplanation& p : probes) {
      if (p.covered) {
        EXPECT_EQ(p.state, ProbeState::kOther);
      }
      if (p.state != ProbeState::kOpen) {
        EXPECT_EQ(p.why.by, SupportQuery::OpenBy::kNone);
        continue;
      }
      ++open;
      ASSERT_NE(p.why.by, SupportQuery::OpenBy::kNone);
      const Vector3f& a = p.why.at_m;
      EXPECT_LE((a - n.p_m).head<2>().norm(), float(o.probe_length_m) + 2 * vs);
      if (p.why.by != SupportQuery::OpenBy::kUnobservedStep) {
        const storey::core::map::VoxelKey k{int32_t(std::floor(a.x() / vs)),
                                            int32_t(std::floor(a.y() / vs)),
                                            int32_t(std::floor(a.z() / vs))};
        EXPECT_EQ(h.map.view().occupancy(k), storey::core::map::Occupancy::kUnknown);
      }
    }
    EXPECT_EQ(open, int(n.open_dirs));
    ++checked;
  }
  EXPECT_GT(checked, 0) << "scenario: no C_exp node";
}

TEST(TopologicalFrontiers, StableClusterIdsAcrossUpdates) {
  const World w = split_room();
  Harness h;
  observe_split_room(h, w);
  FrontierClusters fc;
  const auto first = fc.update(h.graph);
  const auto second = fc.update(h.graph);
  ASSERT_EQ(first.size(), second.size());
  for (size_t i = 0; i < first.size(); ++i) {
    EXPECT_EQ(first[i].id, second[i].id);
    EXPECT_EQ(first[i].nodes, second[i].nodes);
  }
}

TEST(TopologicalFrontiers, IncrementalFlagsEqualFullEvaluation) {
  const World w = split_room();
  Harness h;
  observe_split_room(h, w);
  ReachableGraph& g = h.graph;
  std::vector<std::pair<bool, bool>> inc;
  for (NodeId i = 0; i < g.node_capacity(); ++i) inc.emplace_back(g.node(i).c_sur, g.node(i).c_exp);
  TopologicalFrontiers fresh;
  for (NodeId i = 0; i < g.node_capacity(); ++i) {
    if (!g.node(i).alive) continue;
    fresh.evaluate(g, h.map.view(), i);
    EXPECT_EQ(inc[i].first, g.node(i).c_sur) << "node " << i;
    EXPECT_EQ(inc[i].second, g.node(i).c_exp) << "node " << i;
  }
}

TEST(TopologicalFrontiers, AblationSwitchesChangeTheFlagSets) {
  const World w = split_room();
  Harness h;
  observe_split_room(h, w);
  ReachableGraph& g = h.graph;
  auto eval_all = [&](const GraphOptions& o) {
    TopologicalFrontiers tf(o);
    for (NodeId i = 0; i < g.node_capacity(); ++i)
      if (g.node(i).alive) tf.evaluate(g, h.map.view(), i);
  };
  eval_all(GraphOptions{});
  const auto sur = flagged(g, &GraphNode::c_sur), exp = flagged(g, &GraphNode::c_exp);
  ASSERT_FALSE(sur.empty());
  ASSERT_FALSE(exp.empty());
  EXPECT_NE(sur, exp);
  GraphOptions no_sur;
  no_sur.use_c_sur = false;
  eval_all(no_sur);
  EXPECT_TRUE(flagged(g, &GraphNode::c_sur).empty());
  EXPECT_EQ(flagged(g, &GraphNode::c_exp), exp);
  GraphOptions no_exp;
  no_exp.use_c_exp = false;
  eval_all(no_exp);
  EXPECT_TRUE(flagged(g, &GraphNode::c_exp).empty());
  EXPECT_EQ(flagged(g, &GraphNode::c_sur), sur);
  GraphOptions boundary;
  boundary.boundary_frontiers = true;
  eval_all(boundary);
  const auto b = flagged(g, &GraphNode::boundary);
  EXPECT_FALSE(b.empty());
  EXPECT_TRUE(flagged(g, &GraphNode::c_sur).empty());
  EXPECT_TRUE(flagged(g, &GraphNode::c_exp).empty());
  std::set<NodeId> full = sur;
  full.insert(exp.begin(), exp.end());
  EXPECT_NE(b, full);
}

TEST(TopologicalFrontiers, TableTopNeverGetsANode) {
  World w;
  w.add({-4.2f, -4.2f, -0.3f}, {4.2f, 4.2f, 0.0f});
  w.add({-4.2f, -4.2f, 0.0f}, {4.2f, -4.0f, 2.5f});
  w.add({-4.2f, 4.0f, 0.0f}, {4.2f, 4.2f, 2.5f});
  w.add({-4.2f, -4.0f, 0.0f}, {-4.0f, 4.0f, 2.5f});
  w.add({4.0f, -4.0f, 0.0f}, {4.2f, 4.0f, 2.5f});
  // Table: a 1.6 x 1.0 m top at 0.72-0.76 m on four legs.
  w.add({-0.8f, -0.5f, 0.72f}, {0.8f, 0.5f, 0.76f});
  for (float x : {-0.75f, 0.7f})
    for (float y : {-0.45f, 0.4f}) w.add({x, y, 0.0f}, {x + 0.05f, y + 0.05f, 0.72f});
  Harness h;
  const Vector3f foot(-2.5f, 0, 0);
  h.observe(w, Vector3f(-2.5f, 0, 0.55f), foot, 150000, 1, 6.0f);
  h.observe(w, Vector3f(2.5f, 0, 0.55f), foot, 150000, 2, 6.0f);
  // Views from above (e.g. from a landing) make the table top a well-observed flat surface.
  h.observe(w, Vector3f(0, -2, 1.8f), foot, 150000, 3, 6.0f);
  h.observe(w, Vector3f(0, 2, 1.8f), foot, 150000, 4, 6.0f);
  const auto top = h.map.view().support_surface_near(Vector3f(0, 0, 0.76f), 0.1);
  ASSERT_TRUE(top.has_value()) << "scenario: the table top is not mapped";
  EXPECT_FALSE(top->reachable);
  ASSERT_GT(h.graph.node_count(), 20u);
  for (NodeId i = 0; i < h.graph.node_capacity(); ++i)
    if (h.graph.node(i).alive) {
      EXPECT_LT(h.graph.node(i).p_m.z(), 0.3f)
          << "node on the table at " << h.graph.node(i).p_m.transpose();
    }
}

TEST(ViewpointGenerator, FieldOfViewOfVlp16AndMid360) {
  storey::core::map::TraversabilityMap empty;  // all unknown: nothing occludes
  GraphOptions o;
  SupportQuery q(empty.view(), o);
  ViewpointGenerator vlp(o, SensorFov::vlp16()), mid(o, SensorFov::mid360());
  const Vector3f origin(0, 0, 0.5f);
  const Vector3f low(1.5f, 0, 0.15f);  // -13 deg: VLP-16 only
  const Vector3f high(1.0f, 0, 1.5f);  // +45 deg: Mid-360 only
  const Vector3f far(40.0f, 0, 0.5f);  // beyond range
  EXPECT_TRUE(vlp.visible(q, origin, 0, low));
  EXPECT_FALSE(mid.visible(q, origin, 0, low));
  EXPECT_FALSE(vlp.visible(q, origin, 0, high));
  EXPECT_TRUE(mid.visible(q, origin, 0, high));
  EXPECT_FALSE(vlp.visible(q, origin, 0, far));
  SensorFov narrow = SensorFov::vlp16();
  narrow.h_fov_deg = 90;
  ViewpointGenerator front(o, narrow);
  EXPECT_TRUE(front.visible(q, origin, 0, Vector3f(3, 0.5f, 0.5f)));
  EXPECT_FALSE(front.visible(q, origin, float(M_PI), Vector3f(3, 0.5f, 0.5f)));
}

TEST(ViewpointGenerator, BestKFacingTheClusterAndOccludedByWalls) {
  const World w = split_room();
  GraphOptions o;
  o.viewpoints_per_cluster = 4;
  Harness h(o);
  observe_split_room(h, w);
  FrontierClusters fc(o);
  const auto& clusters = fc.update(h.graph);
  ASSERT_FALSE(clusters.empty());
  ViewpointGenerator vg(o, SensorFov::vlp16());
  const auto& vps = vg.update(h.graph, h.map.view(), clusters);
  ASSERT_EQ(vps.size(), clusters.size());
  int with_viewpoints = 0;
  for (size_t c = 0; c < clusters.size(); ++c) {
    EXPECT_EQ(vps[c].cluster_id, clusters[c].id);
    EXPECT_LE(vps[c].viewpoints.size(), 4u);
    with_viewpoints += !vps[c].viewpoints.empty();
    for (size_t k = 0; k < vps[c].viewpoints.size(); ++k) {
      const Viewpoint& v = vps[c].viewpoints[k];
      EXPECT_GT(v.visible, 0);
      EXPECT_LE(v.visible, int(clusters[c].nodes.size()));
      if (k) {
        EXPECT_LE(v.visible, vps[c].viewpoints[k - 1].visible);
      }
      const Vector3f d = clusters[c].centroid_m - v.p_m;
      if (std::hypot(d.x(), d.y()) > 0.05f) {
        EXPECT_NEAR(std::remainder(v.yaw_rad - std::atan2(d.y(), d.x()), 2 * M_PI), 0, 1e-4);
      }
    }
  }
  EXPECT_GT(with_viewpoints, 0);
  // The wall occludes: a sensor just east of it does not see a point just west of it.
  SupportQuery q(h.map.view(), o);
  EXPECT_FALSE(
      vg.visible(q, Vector3f(0.6f, -2.0f, 0.5f), float(M_PI), Vector3f(-0.6f, -2.0f, 0.15f)));
  EXPECT_TRUE(vg.visible(q, Vector3f(-2.6f, -2.0f, 0.5f), 0, Vector3f(-0.6f, -2.0f, 0.15f)));
}

TEST(GraphExport, JsonAndPlyDescribeTheGraph) {
  const World w = split_room();
  Harness h;
  observe_split_room(h, w);
  FrontierClusters fc;
  const auto& clusters = fc.update(h.graph);
  const std::string json = to_json(h.graph, &clusters);
  size_t states = 0;
  for (size_t p = json.find("\"state\""); p != std::string::npos; p = json.find("\"state\"", p + 1))
    ++states;
  EXPECT_EQ(states, h.graph.node_count() + h.graph.edge_count());
  EXPECT_NE(json.find("\"clusters\": ["), std::string::npos);
  EXPECT_NE(json.find("\"root\": " + std::to_string(h.graph.root()) + ","), std::string::npos);
  EXPECT_NE(json.find("\"c_sur\": true"), std::string::npos);
  const std::string ply = to_ply(h.graph);
  EXPECT_NE(ply.find("element vertex " + std::to_string(h.graph.node_count()) + "\n"),
            std::string::npos);
  EXPECT_NE(ply.find("element edge " + std::to_string(h.graph.edge_count()) + "\n"),
            std::string::npos);
  std::string err;
  EXPECT_FALSE(write_text_file("/nonexistent-dir/g.ply", ply, &err));
  EXPECT_NE(err.find("/nonexistent-dir/g.ply"), std::string::npos);
}

// C_exp up a stair flight (paper III-C): seen from the floor with the sensor at 0.55 m, the risers
// are observed but the treads above the sensor are not. A probe at body height hits the second
// riser; the climbing probe steps up the observed treads and reaches the unknown ones.
namespace {
// A 12-step flight from x = 0 between side walls, seen from its foot 1.5 m back.
void observe_flight_from_its_foot(Harness& h) {
  World w;
  w.add({-3.2f, -2, -0.3f}, {6, 2, 0.0f});
  w.stairs(0.0f, -0.6f, 0.6f, 0.0f, 12, 0.17f, 0.29f);
  w.add({0, -0.72f, 0}, {3.5f, -0.6f, 2.5f});  // side walls
  w.add({0, 0.6f, 0}, {3.5f, 0.72f, 2.5f});
  w.add({-3.2f, -2, 0}, {-3.0f, 2, 2.5f});  // a wall behind the robot
  h.observe(w, Vector3f(-1.5f, 0, 0.55f), Vector3f(-1.5f, 0, 0), 150000, 7, 6.0f);
}
}  // namespace

TEST(TopologicalFrontiers, ProbeClimbsAStairFlightToItsUnknownTreads) {
  GraphOptions o;
  Harness h(o);
  observe_flight_from_its_foot(h);
  SupportQuery q(h.map.view(), o);
  const Vector3f foot(-0.3f, 0, 0);
  const Eigen::Vector2f up(1, 0), back(-1, 0);
  const float min_free = 0.2f;
  // The level probe stops at a riser: closed.
  EXPECT_FALSE(
      q.probe_open(foot + Vector3f(0, 0, 0.3f), foot + Vector3f(3.0f, 0, 0.3f), min_free, 0.3f));
  bool climbed = false;
  EXPECT_TRUE(q.probe_open_climbing(foot, up, 3.0f, 0.3f, min_free, 0.3f, &climbed));
  EXPECT_TRUE(climbed);  // up a flight: alone it satisfies C_exp (GraphOptions::climb_frontiers)
  // Toward the observed wall behind: closed either way.
  EXPECT_FALSE(q.probe_open_climbing(foot, back, 3.0f, 0.3f, min_free, 0.3f, &climbed));
}

// One step up is no flight: a probe over a curb (or onto the low end of a ramp's side, where the
// ramp's solid rises less than a step) into unknown space is open but has not climbed stairs.
// With climb_frontiers such probes made C_exp frontiers along test_ramp's ramp that no view
// resolved (the upper floor was left at 1-32 %, docs/RESULTS.md session 11).
TEST(TopologicalFrontiers, ProbeOverACurbIsOpenButClimbsNoFlight) {
  World w;
  w.add({-3.2f, -2, -0.3f}, {2.0f, 2, 0.0f});  // floor, ending at x = 2 (unknown beyond)
  w.add({0.0f, -2, -0.3f}, {1.0f, 2, 0.35f});  // a 0.35 m curb, 1 m deep
  w.add({-3.2f, -2, 0}, {-3.0f, 2, 2.5f});     // a wall behind the robot
  GraphOptions o;
  Harness h(o);
  // Seen from high up: the space over the curb is observed free, beyond the floor's end unknown.
  h.observe(w, Vector3f(-1.5f, 0, 2.0f), Vector3f(-1.5f, 0, 0), 150000, 7, 6.0f);
  SupportQuery q(h.map.view(), o);
  bool climbed = true;
  EXPECT_TRUE(q.probe_open_climbing(Vector3f(-0.3f, 0, 0), Eigen::Vector2f(1, 0), 3.0f, 0.3f, 0.2f,
                                    0.3f, &climbed));
  EXPECT_FALSE(climbed);
  // Nor a ramp (GraphOptions::ramp_frontiers): it rose more than a step, but at once, steeply.
  o.ramp_frontiers = true;
  SupportQuery qr(h.map.view(), o);
  climbed = true;
  EXPECT_TRUE(qr.probe_open_climbing(Vector3f(-0.3f, 0, 0), Eigen::Vector2f(1, 0), 3.0f, 0.3f, 0.2f,
                                     0.3f, &climbed));
  EXPECT_FALSE(climbed);
}

// GraphOptions::ramp_frontiers: a 10 deg ramp seen from its foot (sensor 0.55 m up) is seen as
// far as it stays below the sensor; a probe up it climbs the observed surface into the unknown
// beyond. It rose more than a step on the way: with ramp_frontiers it climbed (one such probe
// satisfies C_exp, like a flight's); without, it is an open probe on level-judged ground.
TEST(TopologicalFrontiers, ProbeUpARampClimbsItWithRampFrontiers) {
  World w;
  w.add({-3.2f, -2, -0.3f}, {0.0f, 2, 0.0f});              // floor before the ramp
  w.stairs(0.0f, -0.75f, 0.75f, 0.0f, 60, 0.0176f, 0.1f);  // 10 deg, 6 m, up 1.06 m
  w.add({0.0f, -0.87f, -0.3f}, {6.0f, -0.75f, 2.5f});      // side walls
  w.add({0.0f, 0.75f, -0.3f}, {6.0f, 0.87f, 2.5f});
  w.add({-3.2f, -2, 0}, {-3.0f, 2, 2.5f});  // a wall behind the robot
  for (const bool ramps : {false, true}) {
    GraphOptions o;
    o.ramp_frontiers = ramps;
    Harness h(o);
    h.observe(w, Vector3f(-1.5f, 0, 0.55f), Vector3f(-1.5f, 0, 0), 150000, 7, 8.0f);
    SupportQuery q(h.map.view(), o);
    const Vector3f foot(0.5f, 0, 0.09f);
    bool climbed = !ramps;
    EXPECT_TRUE(
        q.probe_open_climbing(foot, Eigen::Vector2f(1, 0), 3.0f, 0.3f, 0.2f, 0.3f, &climbed))
        << "ramp_frontiers " << ramps;
    EXPECT_EQ(climbed, ramps);
    // Level ground toward the wall behind: closed; nothing climbed.
    climbed = false;
    EXPECT_FALSE(q.probe_open_climbing(Vector3f(-1.0f, 0, 0), Eigen::Vector2f(-1, 0), 3.0f, 0.3f,
                                       0.2f, 0.3f, &climbed));
    EXPECT_FALSE(climbed);
  }
}

// A wall seen only at grazing angles keeps voxel-sized holes; behind them lies the wall's solid,
// never observable. A C_exp probe entering unknown space through such a hole is closed (in
// test_ramp's corridors these holes made frontiers no view could resolve); one through the
// open end of a room stays open. Experimental, off by default (GraphOptions::
// close_probes_at_holes).
TEST(TopologicalFrontiers, ProbeThroughAHoleInAWallIsClosed) {
  // Seen from origins up to the wall so the space in front of it is observed free; from the
  // oblique ones a ray to a point beside the hole may cross the hole's voxel (carved free).
  storey::core::map::TraversabilityMap m;
  std::vector<Vector3f> pts;
  for (float x = -1.95f; x < 2.0f; x += 0.1f)  // floor, up to the wall
    for (float y = -1.95f; y < 2.0f; y += 0.1f) pts.push_back({x, y, -0.05f});
  for (float y = -1.95f; y < 2.0f; y += 0.1f)  // wall face at x = 2.05 (solid behind it)
    for (float z = 0.05f; z < 1.5f; z += 0.1f) {
      const bool hole = std::abs(y - 0.05f) < 0.01f && std::abs(z - 0.35f) < 0.01f;
      if (!hole) pts.push_back({2.05f, y, z});
    }
  for (const float ox : {0.0f, 1.0f, 1.7f})
    for (const float oy : {-0.5f, 0.0f, 0.5f}) {
      m.insert_scan(Vector3f(ox, oy, 0.55f), pts);
      m.update_traversability();
    }
  for (const bool on : {true, false}) {
    SCOPED_TRACE(on ? "graph.close_probes_at_holes on" : "off");
    GraphOptions opt;
    opt.close_probes_at_holes = on;
    SupportQuery q(m.view(), opt);
    const Vector3f foot(0.05f, 0.05f, 0.0f);
    // Straight into the hole at the probe's height (0.3 m over the floor: voxel 0.3-0.4).
    EXPECT_EQ(q.probe_open_climbing(foot, Eigen::Vector2f(1, 0), 3.0f, 0.3f, 0.2f, 0.3f), !on);
    // Toward the room's unobserved side (no wall there): open either way.
    EXPECT_TRUE(q.probe_open_climbing(foot, Eigen::Vector2f(0, 1), 3.0f, 0.3f, 0.2f, 0.3f));
  }
}

// A wall's face that straddles a voxel boundary is hit at some heights only: a voxel of the face
// with free space over it looks like a tread seen edge-on (N(v) < N_min), and a probe "steps up"
// onto it into open terrain (teaching_building seed 1: C_exp frontiers along every explored
// room's walls drew the robot back for 300 s). With graph.close_probes_at_wall_faces the wall
// rising on behind that voxel closes the probe; a flight's treads still let it climb.
TEST(TopologicalFrontiers, AWallsFaceIsNoStepWithCloseProbesAtWallFaces) {
  storey::core::map::TraversabilityMap m;
  std::vector<Vector3f> pts;
  for (float x = -1.95f; x < 2.0f; x += 0.1f)  // floor, up to the wall
    for (float y = -1.95f; y < 2.0f; y += 0.1f) pts.push_back({x, y, -0.05f});
  for (float y = -1.95f; y < 2.0f; y += 0.1f)  // wall: face voxels x 2.0-2.1, solid behind
    for (float z = 0.05f; z < 1.5f; z += 0.1f)
      for (const float x : {2.05f, 2.15f}) pts.push_back({x, y, z});
  // The face's near voxel column (x 1.9-2.0) hit at 0.3-0.4 m only (rays carve it free above
  // and below): one return straight ahead of the robot.
  const Vector3f face(1.99f, 0.05f, 0.35f);
  for (const float ox : {0.0f, 1.0f})
    for (const float oy : {-0.5f, 0.0f, 0.5f}) {
      std::vector<Vector3f> scan = pts;
      scan.push_back(face);
      m.insert_scan(Vector3f(ox, oy, 0.55f), scan);
      m.update_traversability();
    }
  const Vector3f foot(0.05f, 0.05f, 0.0f);
  for (const bool on : {false, true}) {
    SCOPED_TRACE(on ? "graph.close_probes_at_wall_faces on" : "off");
    GraphOptions opt;
    opt.close_probes_at_wall_faces = on;
    SupportQuery q(m.view(), opt);
    EXPECT_EQ(q.probe_open_climbing(foot, Eigen::Vector2f(1, 0), 3.0f, 0.3f, 0.2f, 0.3f), !on);
    // Beside it, where the face is hit at every height: closed either way.
    EXPECT_FALSE(q.probe_open_climbing(Vector3f(0.05f, -1.05f, 0.0f), Eigen::Vector2f(1, 0), 3.0f,
                                       0.3f, 0.2f, 0.3f));
  }
}

// ... and up a flight of stairs the probe climbs as before: behind each riser's top lies its
// tread, free over it.
TEST(TopologicalFrontiers, ProbeClimbsAFlightWithCloseProbesAtWallFaces) {
  GraphOptions o;
  o.close_probes_at_wall_faces = true;
  Harness h(o);
  observe_flight_from_its_foot(h);
  SupportQuery q(h.map.view(), o);
  bool climbed = false;
  EXPECT_TRUE(q.probe_open_climbing(Vector3f(-0.3f, 0, 0), Eigen::Vector2f(1, 0), 3.0f, 0.3f, 0.2f,
                                    0.3f, &climbed));
  EXPECT_TRUE(climbed);
}

// GraphOptions::surface_seen_from_above: a 0.2 m slab seen from the floor below, then its top
// seen from above near one end only. Off, Eq. 5 takes the slab's underside, within a step of the
// upper floor's nodes, for the floor beyond what was seen: no node there is C_sur (test_ramp
// seed 2's gallery strips, session 18). On, the nodes at the edge of the seen part are.
TEST(TopologicalFrontiers, ASlabSeenFromBelowIsNoSurfaceForTheFloorAbove) {
  World w;
  w.add({0, -2, -0.3f}, {10, 2, 0.0f});          // ground floor
  w.add({0, -2, 2.8f}, {10, 2, 3.0f});           // the upper floor's slab
  w.add({-0.2f, -2.2f, -0.3f}, {10.2f, -2, 6});  // walls around both floors
  w.add({-0.2f, 2, -0.3f}, {10.2f, 2.2f, 6});
  w.add({-0.2f, -2, -0.3f}, {0, 2, 6});
  w.add({10, -2, -0.3f}, {10.2f, 2, 6});
  for (const bool on : {false, true}) {
    SCOPED_TRACE(on ? "graph.surface_seen_from_above on" : "off");
    GraphOptions o;
    o.surface_seen_from_above = on;
    o.use_c_exp = false;  // C_sur alone
    Harness h(o);
    h.observe(w, Vector3f(5, 0, 0.55f), Vector3f(5, 0, 0), 150000, 1, 12.0f);
    h.observe(w, Vector3f(1, 0, 3.45f), Vector3f(1, 0, 3.0f), 150000, 2, 2.5f);
    int upper = 0, c_sur = 0;
    float rho_max = 0;
    for (NodeId i = 0; i < h.graph.node_capacity(); ++i) {
      const GraphNode& n = h.graph.node(i);
      if (!n.alive || n.p_m.z() < 2.5f) continue;
      ++upper;
      c_sur += n.c_sur;
      rho_max = std::max(rho_max, n.rho);
    }
    ASSERT_GT(upper, 3);
    if (on) {
      EXPECT_GT(c_sur, 0);
      EXPECT_GE(rho_max, 0.3f);
    } else {
      EXPECT_EQ(c_sur, 0) << "rho max " << rho_max;
    }
  }
}

// With MapOptions::floor_seen_from_above a slab seen only from below is S_untrav, and
// SupportQuery says it is an underside: Eq. 5 counts it as missing even where rays grazing the
// floor above carved the voxels over it free (test_ramp seed 4's corridors). Its top, once seen
// from above, is the surface and no underside.
TEST(SupportQuery, ASlabSeenOnlyFromBelowIsAnUnderside) {
  World w;
  w.add({-6, -6, -0.3f}, {6, 6, 0.0f});  // ground floor
  w.add({-6, -6, 2.8f}, {6, 6, 3.0f});   // the upper floor's slab
  World upper;
  upper.add({-6, -6, 2.8f}, {6, 6, 3.0f});
  for (const bool on : {false, true}) {
    SCOPED_TRACE(on ? "map.floor_seen_from_above on" : "off");
    storey::core::map::MapOptions mo;
    mo.spill_is_surface = mo.miss_needs_crossing = true;  // as in config/default.yaml
    mo.floor_seen_from_above = on;
    storey::core::map::TraversabilityMap m(mo);
    uint32_t seed = 1;
    for (const float x : {-2.0f, 0.0f, 2.0f}) {
      const Vector3f o(x, 0.3f, 0.55f);
      m.insert_scan(o, storey::test::graph::scan(w, o, 60000, seed++, 12.0f));
    }
    m.update_traversability();
    // Samples over the middle, within a step of the upper floor (3.0 m).
    auto count = [&](int* found, int* under) {
      SupportQuery q(m.view(), GraphOptions{});
      *found = *under = 0;
      for (float x = -1.95f; x < 2.0f; x += 0.3f)
        for (float y = -1.95f; y < 2.0f; y += 0.3f)
          if (const auto s = q.surface_near(x, y, 3.0f, 0.2f)) {
            ++*found;
            *under += s->underside;
          }
    };
    int found = 0, under = 0;
    count(&found, &under);
    EXPECT_GE(found, 150);  // of 196
    if (on)
      EXPECT_GE(under, found * 9 / 10);
    else
      EXPECT_EQ(under, 0);
    for (const float x : {-2.0f, 0.0f, 2.0f}) {
      const Vector3f o(x, 0.3f, 3.55f);
      m.insert_scan(o, storey::test::graph::scan(upper, o, 60000, seed++, 12.0f));
    }
    m.update_traversability();
    count(&found, &under);
    EXPECT_GE(found, 150);
    EXPECT_EQ(under, 0);
  }
}

// GraphOptions::climb_frontiers: a walled flight ending at a landing with a wall ahead (the first
// flight of a U-shaped stair), seen from the floor. The back of each tread near the sensor's
// height is shadowed by the next riser: the treads are support, but C_reach does not join them
// to the floor. The graph cannot follow the flight; the nodes near its foot are flight leads
// (GraphNode::flight_lead), where the planner goes once the floor has no other target
// (teaching_building seed 1, session 23: seen from the side, the flight's foot frontier was cleared
// and the stairs never climbed).
TEST(TopologicalFrontiers, AFlightRisingOutOfTheReachableSetIsAFlightLead) {
  World w;
  w.add({-3.2f, -2, -0.3f}, {6, 2, 0.0f});
  w.stairs(0.0f, -0.6f, 0.6f, 0.0f, 7, 0.17f, 0.29f);  // up to 1.19 m at x = 2.03
  w.add({2.03f, -0.6f, -0.3f}, {3.4f, 0.6f, 1.19f});   // the landing
  w.add({3.4f, -0.72f, 0}, {3.6f, 0.72f, 3.5f});       // its wall
  w.add({0, -0.72f, 0}, {3.4f, -0.6f, 3.5f});          // side walls
  w.add({0, 0.6f, 0}, {3.4f, 0.72f, 3.5f});
  w.add({-3.2f, -2, 0}, {-3.0f, 2, 2.5f});  // a wall behind the robot
  for (const bool on : {true, false}) {
    SCOPED_TRACE(on ? "climb_frontiers on" : "off");
    GraphOptions o;
    o.climb_frontiers = on;
    Harness h(o);
    for (const float x : {-2.5f, -1.5f, -0.8f})
      h.observe(w, Vector3f(x, 0.1f, 0.62f), Vector3f(x, 0.1f, 0), 150000, 7, 8.0f);
    // The premise: a tread near the top is support the map holds, out of C_reach.
    const auto top = h.map.view().support_surface_near(Vector3f(1.75f, 0.05f, 1.19f), 0.1);
    ASSERT_TRUE(top.has_value());
    EXPECT_FALSE(top->reachable);
    SupportQuery q(h.map.view(), o);
    bool climbed = false, leaves = false;
    q.probe_open_climbing(Vector3f(-0.3f, 0, 0), Eigen::Vector2f(1, 0), 3.0f, 0.3f, 0.2f, 0.3f,
                          &climbed, &leaves);
    EXPECT_TRUE(climbed);
    EXPECT_TRUE(leaves);
    // Flight leads: with the option, nodes within a probe's length of the flight's foot.
    int leads = 0, far = 0;
    for (NodeId i = 0; i < h.graph.node_capacity(); ++i) {
      const auto& n = h.graph.node(i);
      if (!n.alive || !n.flight_lead) continue;
      ++leads;
      far += n.p_m.head<2>().norm() > 3.2f;
    }
    EXPECT_EQ(leads > 0, on) << leads;
    EXPECT_EQ(far, 0);
  }
}

// GraphOptions::passage_frontiers: an open C_exp probe between two probes blocked by obstacles
// (walls either side) is a passage; a neighbour that ran out in known free space, or started in
// unknown space, is not a wall (session 26's rule counted one of them).
TEST(TopologicalFrontiers, APassageIsAnOpenProbeBetweenTwoBlockedOnes) {
  using P = ProbeState;
  const P o = P::kOpen, b = P::kBlocked, x = P::kOther;
  const auto count = [](std::vector<P> ring) { return passage_probes(ring); };
  EXPECT_EQ(count({o, b, x, x, x, b}), 1);  // neighbours wrap around the ring
  EXPECT_EQ(count({b, o, b, o, b, x}), 2);
  EXPECT_EQ(count({x, o, b, x}), 0);  // one side not a wall
  EXPECT_EQ(count({o, o, b, b}), 0);  // two open probes: plain C_exp (Theta_min), not a passage
  EXPECT_EQ(count({b, o}), 0);        // too few probes to have two neighbours
  EXPECT_EQ(count({}), 0);
}

// A 1 m corridor seen to 3 m from its closed end: at the graph's end one probe runs on along it
// into unknown space; the probes 30 deg either side meet its walls or start in air the scan left
// unknown. One open probe is below Theta_min = 2 (with close_probes_at_wall_faces no phantom
// step adds a second). A neighbour in unknown air is not a wall, so no passage either (in
// test_ramp's upper corridors, session 28, the LiDAR saw the walls well beyond the floor and both
// were blocked: there the switch made the corridors' ends frontiers).
TEST(TopologicalFrontiers, ACorridorsEndSeenOnlyAsFarAsItsFloorIsNoPassage) {
  World w;
  w.add({-1.2f, -0.7f, -0.3f}, {20, 0.7f, 0.0f});
  w.add({-1.2f, -0.7f, 0.0f}, {20, -0.5f, 2.5f});
  w.add({-1.2f, 0.5f, 0.0f}, {20, 0.7f, 2.5f});
  w.add({-1.2f, -0.5f, 0.0f}, {-1.0f, 0.5f, 2.5f});
  for (const bool on : {false, true}) {
    SCOPED_TRACE(on ? "graph.passage_frontiers on" : "off");
    GraphOptions o;
    o.close_probes_at_holes = o.close_probes_at_wall_faces = true;  // as in config/default.yaml
    o.passage_frontiers = on;
    Harness h(o);
    h.observe(w, Vector3f(0, 0, 0.55f), Vector3f(0, 0, 0), 100000, 7, 3.0f);
    int passages = 0, others = 0;  // C_exp nodes with one open probe / more
    float max_x = -1;
    for (NodeId i = 0; i < h.graph.node_capacity(); ++i) {
      const GraphNode& n = h.graph.node(i);
      if (!n.alive) continue;
      max_x = std::max(max_x, n.p_m.x());
      if (!n.c_exp) continue;
      (n.open_dirs == 1 ? passages : others) += 1;
      EXPECT_GT(n.p_m.x(), 0.5f);  // the open end, not the closed one
    }
    ASSERT_GT(max_x, 0.5f);  // the graph reached along the corridor
    EXPECT_EQ(others, 0);
    EXPECT_EQ(passages, 0);
  }
}
