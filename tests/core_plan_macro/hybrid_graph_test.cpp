#include "core/plan/hybrid_graph.hpp"

#include <gtest/gtest.h>

#include "macro_world.hpp"
#include "toy_graph.hpp"

using namespace storey::core::plan;
using storey::test::macro::Harness;
using storey::test::macro::Room;
using storey::test::macro::ToyGraph;
using storey::test::macro::World;

namespace {

// Compiled node nearest p among those standing for a hypothesis or a real node.
uint32_t nearest(const HybridGraph& hg, const Eigen::Vector3d& p) {
  uint32_t best = kNoNode;
  double bd = 1e9;
  for (uint32_t u = 0; u < hg.nodes().size(); ++u) {
    const double d = (hg.nodes()[u].p_m - p).norm();
    if (d < bd) {
      bd = d;
      best = u;
    }
  }
  return best;
}

// Two rooms on one floor: A = [0,6] x [0,5], B = [6.2,12] x [0,5]; door in the dividing wall
// at y in [2,3] only if `door_open`.
World two_room_world(bool door_open) {
  World w;
  w.add({-1, -1, -0.2f}, {13, 6, 0});
  w.add({-0.2f, -0.2f, 0}, {0, 5.2f, 2.5f});
  w.add({12, -0.2f, 0}, {12.2f, 5.2f, 2.5f});
  w.add({-0.2f, -0.2f, 0}, {12.2f, 0, 2.5f});
  w.add({-0.2f, 5, 0}, {12.2f, 5.2f, 2.5f});
  if (door_open) {
    w.add({6, 0, 0}, {6.2f, 2, 2.5f});
    w.add({6, 3, 0}, {6.2f, 5, 2.5f});
  } else {
    w.add({6, 0, 0}, {6.2f, 5, 2.5f});
  }
  return w;
}

// The reference floor's graph: the same two rooms with an open door, one zone spanning both.
struct Prior {
  ToyGraph t;
  SearchGraph g;
  ZonePartition zones;
  Prior() {
    t.add_room({0, 0, 6, 5}, 0.8, 0);
    t.add_room({6.2, 0, 12, 5}, 0.8, 1);
    t.link(t.nearest({5.6, 2.4, 0}), t.nearest({6.6, 2.4, 0}));
    g = t.csr();
    TaskZonePartitioner p;
    zones = p.partition(g, t.clearance, {30.0, 4});
  }
};

}  // namespace

TEST(HybridGraph, ClosedDoorSplitsTheZoneAndReassignsTheCutOffPart) {
  Prior prior;
  ASSERT_EQ(prior.zones.zones.size(), 1u);  // one zone through the door on the reference floor
  const World w = two_room_world(/*door_open=*/false);
  for (bool maintain : {true, false}) {
    Harness h;
    FloorTracker ft;
    ft.update(Eigen::Vector3d::Zero(), 0.0);
    HybridGraph hg;
    hg.init_prior(prior.g, prior.zones, 0.0, 0);
    PlanOptions opt;
    opt.incremental_maintenance = maintain;
    MaintenanceStats st;
    uint32_t seed = 1;
    for (const Eigen::Vector3f& foot : {Eigen::Vector3f(3, 2.5f, 0), Eigen::Vector3f(5, 2.5f, 0)}) {
      h.observe(w, foot, 30000, seed++);
      st = hg.update(h.map.view(), h.map.version(), h.graph, ft, foot.cast<double>(), opt);
    }
    const uint32_t a = nearest(hg, {3, 2.5, 0}), b = nearest(hg, {9, 2.5, 0});
    ASSERT_NE(a, kNoNode);
    ASSERT_NE(b, kNoNode);
    EXPECT_TRUE(hg.node_real(a));
    EXPECT_FALSE(hg.node_real(b));  // room B is never seen: still a hypothesis
    if (maintain) {
      EXPECT_NE(hg.nodes()[a].zone, hg.nodes()[b].zone) << "zone still spans the closed door";
      EXPECT_GE(hg.nodes()[b].zone, 0) << "cut-off part left unassigned";
      // Every room-B hypothesis shares one zone (reassigned as a whole), of state H.
      for (const HybridZone& z : hg.zones()) {
        bool has_b = false, has_a = false;
        for (uint32_t u : z.nodes) {
          has_b = has_b || hg.nodes()[u].p_m.x() > 6.1;
          has_a = has_a || hg.nodes()[u].p_m.x() < 6.0;
        }
        EXPECT_FALSE(has_a && has_b) << "zone " << z.id;
        if (has_b) {
          EXPECT_EQ(z.state, ZoneState::kHypothetical);
        }
        if (has_a) {
          EXPECT_NE(z.state, ZoneState::kHypothetical);
        }
      }
    } else {
      // Ablation: the prior's zones stay as projected.
      EXPECT_EQ(hg.nodes()[a].zone, hg.nodes()[b].zone);
    }
  }
}

TEST(HybridGraph, HypothesisConfirmedWhenObservedAndDiscardedAfterRepeatedEmptyObservations) {
  // Target floor: floor slab only for x < 4; beyond, a pit 0.8 m deep up to a wall at x = 10
  // (the prior expects floor over the pit).
  World w;
  w.add({-1, -1, -0.2f}, {4, 5, 0});
  w.add({-1, -1, -1.0f}, {10, 5, -0.8f});
  w.add({10, -1, -1.0f}, {10.2f, 5, 2.5f});
  ToyGraph t;
  t.add_room({0, 0, 6.4, 4}, 0.8, 0);
  const SearchGraph g = t.csr();
  TaskZonePartitioner part;
  const ZonePartition zones = part.partition(g, t.clearance, {6.0, 4});
  Harness h;
  FloorTracker ft;
  ft.update(Eigen::Vector3d::Zero(), 0.0);
  HybridGraph hg;
  hg.init_prior(g, zones, 0.0, 0);
  PlanOptions opt;
  opt.hyp_discard_observations = 3;
  const Eigen::Vector3f foot(3, 2, 0);
  const size_t total = hg.hypotheses_alive();
  std::vector<MaintenanceStats> st;
  for (uint32_t i = 0; i < 4; ++i) {
    h.observe(w, foot, 30000, 10 + i);
    st.push_back(hg.update(h.map.view(), h.map.version(), h.graph, ft, foot.cast<double>(), opt));
  }
  // Confirmed: the hypotheses over the slab merged with real nodes or promoted.
  EXPECT_GT(st[0].bound + st[0].promoted, 0u);
  const uint32_t on_slab = nearest(hg, {1.2, 1.2, 0});
  EXPECT_TRUE(hg.node_real(on_slab));
  // Over the atrium: negative evidence on each new map version, discarded at the third.
  EXPECT_GT(st[0].negative, 0u);
  EXPECT_EQ(st[0].discarded, 0u);
  EXPECT_EQ(st[1].discarded, 0u);
  EXPECT_GT(st[2].discarded, 0u);
  // (The outer rows look past the end of the far wall: never observed, never discarded.)
  for (const HybridNode& n : hg.nodes()) {
    if (n.real == storey::core::graph::kNoId && std::abs(n.p_m.y() - 2.0) < 1.5) {
      EXPECT_LT(n.p_m.x(), 4.0 + opt.hyp_promote_radius_m + 0.1)
          << "hypothesis over the pit at y " << n.p_m.y() << " z " << n.p_m.z() << " state "
          << int(n.state);
    }
  }
  EXPECT_LT(hg.hypotheses_alive(), total);
  // The same map version twice counts once.
  const MaintenanceStats again =
      hg.update(h.map.view(), h.map.version(), h.graph, ft, foot.cast<double>(), opt);
  EXPECT_EQ(again.negative, 0u);
}

TEST(HybridGraph, ChangedRegionsLimitReChecksToWhereTheMapChanged) {
  // The pit world of the previous test, both graphs fed the same scans.
  World w;
  w.add({-1, -1, -0.2f}, {4, 5, 0});
  w.add({-1, -1, -1.0f}, {10, 5, -0.8f});
  w.add({10, -1, -1.0f}, {10.2f, 5, 2.5f});
  ToyGraph t;
  t.add_room({0, 0, 6.4, 4}, 0.8, 0);
  const SearchGraph g = t.csr();
  TaskZonePartitioner part;
  const ZonePartition zones = part.partition(g, t.clearance, {6.0, 4});
  Harness h;
  FloorTracker ft;
  ft.update(Eigen::Vector3d::Zero(), 0.0);
  HybridGraph full, regions;
  full.init_prior(g, zones, 0.0, 0);
  regions.init_prior(g, zones, 0.0, 0);
  PlanOptions opt;
  opt.hyp_discard_observations = 10;  // none discarded: evidence keeps counting
  const Eigen::Vector3f foot(3, 2, 0);
  // Each scan changes the whole room: a region covering it re-checks what the full check does.
  std::vector<storey::core::graph::Aabb> room(1);
  room[0].extend({-1, -1, -1.5f});
  room[0].extend({11, 6, 3});
  for (uint32_t i = 0; i < 4; ++i) {
    h.observe(w, foot, 30000, 10 + i);
    const auto view = h.map.view();
    const MaintenanceStats a =
        full.update(view, h.map.version(), h.graph, ft, foot.cast<double>(), opt);
    const MaintenanceStats b =
        regions.update(view, h.map.version(), h.graph, ft, foot.cast<double>(), opt, &room);
    EXPECT_EQ(a.promoted, b.promoted) << i;
    EXPECT_EQ(a.negative, b.negative) << i;
    EXPECT_EQ(a.discarded, b.discarded) << i;
    EXPECT_EQ(a.edges_confirmed, b.edges_confirmed) << i;
    EXPECT_EQ(a.edges_pruned, b.edges_pruned) << i;
  }
  EXPECT_EQ(full.hypotheses_alive(), regions.hypotheses_alive());
  // A new version that changed nothing near the hypotheses: the full check counts negative
  // evidence again, the region-aware one re-checks nothing (no new observation of a column).
  const std::vector<storey::core::graph::Aabb> elsewhere = {
      storey::core::graph::Aabb{{50, 50, 0}, {52, 52, 1}}};
  const auto view = h.map.view();
  const uint64_t v = h.map.version() + 1;
  EXPECT_GT(full.update(view, v, h.graph, ft, foot.cast<double>(), opt).negative, 0u);
  const MaintenanceStats none =
      regions.update(view, v, h.graph, ft, foot.cast<double>(), opt, &elsewhere);
  EXPECT_EQ(none.negative + none.promoted + none.edges_pruned + none.edges_confirmed, 0u);
}

TEST(HybridGraph, HypothesesComingIntoRangeAreCheckedWithoutAChangeNearThem) {
  World w;
  w.add({-1, -1, -0.2f}, {4, 5, 0});
  w.add({-1, -1, -1.0f}, {10, 5, -0.8f});
  w.add({10, -1, -1.0f}, {10.2f, 5, 2.5f});
  ToyGraph t;
  t.add_room({0, 0, 6.4, 4}, 0.8, 0);
  const SearchGraph g = t.csr();
  TaskZonePartitioner part;
  const ZonePartition zones = part.partition(g, t.clearance, {6.0, 4});
  Harness h;
  FloorTracker ft;
  ft.update(Eigen::Vector3d::Zero(), 0.0);
  HybridGraph hg;
  hg.init_prior(g, zones, 0.0, 0);
  PlanOptions opt;
  opt.hyp_check_radius_m = 2.0;
  const Eigen::Vector3f foot(3, 2, 0);
  h.observe(w, foot, 30000, 10);
  const auto view = h.map.view();
  // The robot (as far as the check radius goes) is away from the pit: nothing over it checked.
  const Eigen::Vector3d away(-10, 2, 0);
  hg.update(view, h.map.version(), h.graph, ft, away, opt);
  const std::vector<storey::core::graph::Aabb> none;
  // It comes near the pit on a version that changed nothing: the columns now in range are
  // checked once (negative evidence over the pit), then not again until the map changes.
  const Eigen::Vector3d near_pit(5.5, 2, 0);
  const MaintenanceStats a =
      hg.update(view, h.map.version() + 1, h.graph, ft, near_pit, opt, &none);
  EXPECT_GT(a.negative, 0u);
  const MaintenanceStats b =
      hg.update(view, h.map.version() + 2, h.graph, ft, near_pit, opt, &none);
  EXPECT_EQ(b.negative, 0u);
}
