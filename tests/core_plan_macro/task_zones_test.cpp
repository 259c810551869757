#include "core/plan/task_zones.hpp"

#include <gtest/gtest.h>

#include <set>

#include "macro_world.hpp"
#include "toy_graph.hpp"

using namespace storey::core::plan;
using storey::test::macro::Room;
using storey::test::macro::ToyGraph;

namespace {

// Nodes of zone z reachable from its centre along edges inside the zone.
size_t reachable_inside(const SearchGraph& g, const ZonePartition& p, int32_t z) {
  std::vector<uint8_t> seen(g.num_nodes(), 0);
  std::vector<uint32_t> st{p.zones[size_t(z)].centre};
  seen[st[0]] = 1;
  size_t n = 0;
  while (!st.empty()) {
    const uint32_t u = st.back();
    st.pop_back();
    ++n;
    g.for_each_edge(u, [&](uint32_t v, double, uint32_t) {
      if (!seen[v] && p.zone_of[v] == z) {
        seen[v] = 1;
        st.push_back(v);
      }
    });
  }
  return n;
}

ToyGraph two_rooms(bool door, uint32_t* door_a = nullptr, uint32_t* door_b = nullptr) {
  ToyGraph t;
  t.add_room({0, 0, 10, 8}, 0.5, 0);
  t.add_room({10.2, 0, 20.2, 8}, 0.5, 1);
  const uint32_t a = t.nearest({9.75, 4.25, 0}), b = t.nearest({10.45, 4.25, 0});
  if (door) t.link(a, b);
  if (door_a) *door_a = a;
  if (door_b) *door_b = b;
  return t;
}

}  // namespace

TEST(TaskZones, NoZoneSpansAWallWithoutADoor) {
  ToyGraph t = two_rooms(false);
  const SearchGraph g = t.csr();
  TaskZonePartitioner part;
  const ZonePartition p = part.partition(g, t.clearance, {6.0, 4});
  ASSERT_GE(p.zones.size(), 2u);
  for (const TaskZone& z : p.zones) {
    std::set<int> rooms;
    for (uint32_t u : z.nodes) rooms.insert(t.room_of[u]);
    EXPECT_EQ(rooms.size(), 1u) << "zone " << z.id << " spans the wall";
  }
  // The nodes 0.7 m apart across the wall are in different zones.
  const uint32_t a = t.nearest({9.75, 4.25, 0}), b = t.nearest({10.45, 4.25, 0});
  EXPECT_NE(p.zone_of[a], p.zone_of[b]);
}

TEST(TaskZones, ZonesFollowGraphConnectivityThroughADoor) {
  uint32_t da, db;
  ToyGraph t = two_rooms(true, &da, &db);
  const SearchGraph g = t.csr();
  TaskZonePartitioner part;
  const ZonePartition p = part.partition(g, t.clearance, {6.0, 4});
  size_t covered = 0;
  for (const TaskZone& z : p.zones) {
    covered += z.nodes.size();
    EXPECT_EQ(reachable_inside(g, p, z.id), z.nodes.size()) << "zone " << z.id << " is split";
    std::set<int> rooms;
    for (uint32_t u : z.nodes) rooms.insert(t.room_of[u]);
    if (rooms.size() > 1) {  // spans the wall: only through the doorway
      EXPECT_EQ(p.zone_of[da], z.id);
      EXPECT_EQ(p.zone_of[db], z.id);
    }
    EXPECT_GE(z.nodes.size(), 4u);
    EXPECT_EQ(p.zone_of[z.centre], z.id);
  }
  EXPECT_EQ(covered, t.pos.size());
  for (int32_t z : p.zone_of) EXPECT_GE(z, 0);
}

TEST(TaskZones, FirstSeedIsTheNodeFarthestFromObstaclesAndCentreNearestTheCentroid) {
  ToyGraph t;
  t.add_room({0, 0, 4, 4}, 0.5, 0);  // one zone: r_z larger than the room
  const SearchGraph g = t.csr();
  TaskZonePartitioner part;
  const ZonePartition p = part.partition(g, t.clearance, {20.0, 1});
  ASSERT_EQ(p.zones.size(), 1u);
  const TaskZone& z = p.zones[0];
  EXPECT_NEAR(z.centroid_m.x(), 2.0, 1e-9);
  EXPECT_NEAR(z.centroid_m.y(), 2.0, 1e-9);
  // Four nodes tie at 0.35 m from (2, 2); the lowest index wins.
  EXPECT_NEAR((t.pos[z.centre] - z.centroid_m).norm(), std::sqrt(0.125), 1e-9);
}

TEST(TaskZones, SmallZonesAreAbsorbedIntoTheNeighbourWithMostCrossEdges) {
  ToyGraph t;
  t.add_room({0, 0, 6, 6}, 0.5, 0);
  // A two-node alcove far along a thin corridor of one edge: its own zone by r_z, then absorbed.
  const uint32_t tip = t.nearest({5.75, 3.25, 0});
  const size_t first = t.pos.size();
  for (int i = 0; i < 2; ++i) {
    t.pos.emplace_back(12.0 + i * 0.5, 3.25, 0);
    t.room_of.push_back(1);
    t.clearance.push_back(0.25);
  }
  t.link(tip, uint32_t(first));
  t.link(uint32_t(first), uint32_t(first + 1));
  const SearchGraph g = t.csr();
  TaskZonePartitioner part;
  ZonePartition p = part.partition(g, t.clearance, {3.0, 4});
  EXPECT_EQ(p.zone_of[first], p.zone_of[tip]);
  EXPECT_EQ(p.zone_of[first + 1], p.zone_of[tip]);
  for (const TaskZone& z : p.zones) EXPECT_GE(z.nodes.size(), 4u);
  // Without absorption the alcove is its own zone.
  p = part.partition(g, t.clearance, {3.0, 1});
  EXPECT_NE(p.zone_of[first], p.zone_of[tip]);
}

TEST(TaskZones, DeterministicAndBadInputIsReported) {
  ToyGraph t = two_rooms(true);
  const SearchGraph g = t.csr();
  TaskZonePartitioner a, b;
  const ZonePartition pa = a.partition(g, t.clearance, {6.0, 4});
  const ZonePartition pb = b.partition(g, t.clearance, {6.0, 4});
  EXPECT_EQ(pa.zone_of, pb.zone_of);
  std::vector<double> short_clearance(3, 1.0);
  const ZonePartition bad = a.partition(g, short_clearance, {6.0, 4});
  EXPECT_TRUE(bad.zones.empty());
  EXPECT_EQ(a.bad_input(), 1u);
}

TEST(ObstacleClearance, BatchedEqualsPointByPoint) {
  // Two rooms with a door, a staircase up to a landing: nodes on several height bands.
  storey::test::macro::World w;
  w.add({-1, -1, -0.2f}, {13, 6, 0});
  w.add({6, 0, 0}, {6.2f, 2, 2.5f});
  w.add({6, 3, 0}, {6.2f, 5, 2.5f});
  w.add({-0.2f, -0.2f, 0}, {12.2f, 0, 2.5f});
  w.stairs(8, 3, 4.5f, 0, 6, 0.15f, 0.3f);
  storey::test::macro::Harness h;
  h.observe(w, {3, 2.5f, 0}, 40000, 1);
  h.observe(w, {9, 2.5f, 0}, 40000, 2);
  std::vector<Eigen::Vector3f> pts;
  for (storey::core::graph::NodeId i = 0; i < h.graph.node_capacity(); ++i)
    if (h.graph.node(i).alive) pts.push_back(h.graph.node(i).p_m);
  ASSERT_GT(pts.size(), 20u);
  pts.push_back({9.5f, 4.0f, 0.6f});  // on the stairs' band
  pts.push_back({3, 2.5f, std::numeric_limits<float>::quiet_NaN()});
  const auto view = h.map.view();
  ObstacleClearance single(2.0), batch(2.0);
  std::vector<double> out;
  batch(view, pts, out);
  ASSERT_EQ(out.size(), pts.size());
  bool some_wall = false;
  for (size_t i = 0; i < pts.size(); ++i) {
    EXPECT_EQ(out[i], single(view, pts[i])) << i;
    some_wall = some_wall || out[i] < 2.0;
  }
  EXPECT_TRUE(some_wall);
}
