#include "core/plan/exploration_planner.hpp"

#include <gtest/gtest.h>

#include "macro_world.hpp"
#include "toy_graph.hpp"

using namespace storey::core::plan;
using storey::test::macro::Harness;
using storey::test::macro::ToyGraph;
using storey::test::macro::World;

namespace {

// Floor 0 slab, a straight staircase of 17 x 0.17 m along +x, floor 1 slab at 2.89 m with two
// rooms (wall at x = 12 with a door) above a hall.
World two_floors() {
  World w;
  w.add({-1, -1, -0.2f}, {10, 6, 0});
  w.stairs(2, 4, 5, 0, 17, 0.17f, 0.28f);
  w.add({-1, -1, 2.69f}, {18, 3.5f, 2.89f});
  return w;
}

ExplorationInput input(const Harness& h, const storey::core::map::MapView& view,
                       const Eigen::Vector3f& foot, double t) {
  ExplorationInput in;
  in.view = &view;
  in.map_version = h.map.version();
  in.graph = &h.graph;
  in.clusters = &h.clusters.clusters();
  in.viewpoints = &h.viewpoints.viewpoints();
  in.robot_foot_m = foot.cast<double>();
  in.t_s = t;
  return in;
}

// The prior `t` (task zones of r_z 5 m) on floor 0, of which only room A (0-6 x 0-5 m) is
// observed, from (2, 2.5): hg's first cycle. Returns the robot's node in hg.
uint32_t prior_over_room_a(const ToyGraph& t, Harness& h, HybridGraph& hg) {
  const SearchGraph g = t.csr();
  TaskZonePartitioner part;
  const ZonePartition zones = part.partition(g, t.clearance, {5.0, 4});
  World w;
  w.add({-1, -1, -0.2f}, {6, 6, 0});
  const Eigen::Vector3f foot(2, 2.5f, 0);
  h.observe(w, foot, 20000, 5);
  FloorTracker ft;
  ft.update(Eigen::Vector3d::Zero(), 0.0);
  hg.init_prior(g, zones, 0.0, 0);
  hg.update(h.map.view(), h.map.version(), h.graph, ft, foot.cast<double>(), PlanOptions{});
  return hg.node_of_real(h.graph.root());
}

}  // namespace

TEST(ExplorationPlanner, FloorChangeBuildsThePriorOnlyWithUsePrior) {
  const World w = two_floors();
  for (bool use_prior : {true, false}) {
    Harness h;
    PlanOptions opt;
    opt.use_prior = use_prior;
    ExplorationPlanner planner({}, opt, 0.1);
    double t = 0;
    // Explore floor 0 a little.
    for (const Eigen::Vector3f& foot : {Eigen::Vector3f(1, 2, 0), Eigen::Vector3f(4, 2, 0)}) {
      h.observe(w, foot, 20000, uint32_t(t * 10) + 1);
      const auto view = h.map.view();
      const ExplorationResult r = planner.plan(input(h, view, foot, t));
      EXPECT_EQ(r.floor, 0);
      EXPECT_FALSE(r.prior_built);
      t += 1.0;
    }
    // Up the stairs and onto floor 1: the floor changes once the height is stable.
    bool changed = false, built = false;
    int32_t ref = -1;
    double dz = 0;
    for (int i = 0; i <= 17; ++i, t += 0.5) {
      const Eigen::Vector3f foot(2.14f + 0.28f * float(i), 4.5f, 0.17f * float(i));
      const auto view = h.map.view();
      changed = changed || planner.plan(input(h, view, foot, t)).floor_changed;
    }
    EXPECT_FALSE(changed) << "a floor change during the climb";
    for (int i = 0; i < 8; ++i, t += 0.5) {  // walking on (a floor needs 1.5 m of level travel)
      const Eigen::Vector3f foot(8 + 0.3f * float(i), 2, 2.89f);
      h.observe(w, foot, 20000, 100 + uint32_t(i));
      const auto view = h.map.view();
      const ExplorationResult r = planner.plan(input(h, view, foot, t));
      if (r.floor_changed) {
        changed = true;
        built = r.prior_built;
        ref = r.reference_floor;
        dz = r.dz_m;
        EXPECT_EQ(r.floor, 1);
      }
    }
    EXPECT_TRUE(changed);
    EXPECT_EQ(planner.floors().current(), 1);
    EXPECT_EQ(built, use_prior);
    EXPECT_EQ(planner.hybrid().has_prior(), use_prior);
    if (use_prior) {
      EXPECT_EQ(ref, 0);
      EXPECT_NEAR(dz, 2.89, 0.15);
      EXPECT_GT(planner.hybrid().hypotheses_alive() + planner.hybrid().nodes().size(), 0u);
    }
  }
}

TEST(ExplorationPlanner, CompleteWhenNoFrontiersAndNoZonesRemain) {
  World w;
  w.add({-1, -1, -0.2f}, {5, 5, 0});
  Harness h;
  const Eigen::Vector3f foot(2, 2, 0);
  h.observe(w, foot, 20000, 3);
  ExplorationPlanner planner({}, PlanOptions{}, 0.1);
  const auto view = h.map.view();
  ExplorationInput in = input(h, view, foot, 0.0);
  const std::vector<storey::core::graph::FrontierCluster> none;
  const std::vector<storey::core::graph::ClusterViewpoints> no_vp;
  in.clusters = &none;
  in.viewpoints = &no_vp;
  const ExplorationResult r = planner.plan(in);
  EXPECT_EQ(r.status, ExplorationStatus::kComplete) << r.reason;
  EXPECT_NE(std::string(r.reason).find("no uncompleted zone"), std::string::npos);
  // With frontiers present the planner is not complete.
  const ExplorationResult r2 = planner.plan(input(h, view, foot, 1.0));
  if (!h.clusters.clusters().empty()) {
    EXPECT_NE(r2.status, ExplorationStatus::kComplete);
  }
}

TEST(ExplorationPlanner, BadInputIsAFailureWithAReason) {
  ExplorationPlanner planner({}, PlanOptions{}, 0.1);
  const ExplorationResult r = planner.plan(ExplorationInput{});
  EXPECT_EQ(r.status, ExplorationStatus::kFailed);
  EXPECT_NE(std::string(r.reason), "");
}

TEST(GlobalPlanner, VisitsTheNearerHypotheticalZoneFirst) {
  // Prior: three rooms in a row joined by doors, one zone each. Target floor: only room A is
  // observed; B and C are hypothetical zones, B nearer.
  ToyGraph t;
  t.add_room({0, 0, 6, 5}, 0.8, 0);
  t.add_room({6.2, 0, 12, 5}, 0.8, 1);
  t.add_room({12.2, 0, 18, 5}, 0.8, 2);
  t.link(t.nearest({5.6, 2.4, 0}), t.nearest({6.6, 2.4, 0}));
  t.link(t.nearest({11.8, 2.4, 0}), t.nearest({12.6, 2.4, 0}));
  Harness h;
  HybridGraph hg;
  const uint32_t robot = prior_over_room_a(t, h, hg);
  ASSERT_NE(robot, kNoNode);
  GlobalPlanner gp;
  const GlobalPlan plan = gp.plan(hg, robot, [](int32_t) { return false; });
  ASSERT_TRUE(plan.ok);
  // Rooms in the visiting order never go back (A, then B, then C; a room may hold two zones).
  std::vector<int> rooms;
  for (int32_t id : plan.zone_order)
    for (const HybridZone& z : hg.zones())
      if (z.id == id) rooms.push_back(int(z.centroid_m.x() / 6.1));
  ASSERT_GE(rooms.size(), 2u);
  for (size_t i = 1; i < rooms.size(); ++i) EXPECT_LE(rooms[i - 1], rooms[i]);
  EXPECT_EQ(rooms.back(), 2);
  EXPECT_GT(plan.hybrid_rows, 0);
  // The path to the farthest zone leaves the real graph: only its real prefix is driven.
  uint32_t far_centre = kNoNode;
  for (const HybridZone& z : hg.zones())
    if (z.id == plan.zone_order.back()) far_centre = z.centre;
  const Approach a = gp.approach(hg, robot, far_centre);
  ASSERT_TRUE(a.ok);
  EXPECT_TRUE(a.used_hybrid);
  EXPECT_LT(a.real_prefix, a.path.size());
  EXPECT_LT(a.goal_m.x(), 6.6);

  // Bounded TSP: with room for one zone only the nearest one enters, the rest are deferred.
  GlobalPlanner one(TspOptions{}, 1);
  const GlobalPlan p1 = one.plan(hg, robot, [](int32_t) { return false; });
  ASSERT_TRUE(p1.ok);
  ASSERT_EQ(p1.zone_order.size(), 1u);
  EXPECT_EQ(p1.deferred, int(plan.zone_order.size()) - 1);
  double nearest = kUnreachable;
  int32_t nearest_id = -1;
  for (int32_t id : plan.zone_order)
    for (const HybridZone& z : hg.zones())
      if (z.id == id) {
        const Approach za = gp.approach(hg, robot, z.centre);
        ASSERT_TRUE(za.ok);
        double len = 0;  // the two-stage cost: real path if any, else the hybrid one
        for (size_t i = 1; i < za.path.size(); ++i)
          len += (hg.nodes()[za.path[i]].p_m - hg.nodes()[za.path[i - 1]].p_m).norm();
        if (len < nearest) nearest = len, nearest_id = id;
      }
  EXPECT_EQ(p1.zone_order.front(), nearest_id);
  // With room for every zone the order is the unbounded one.
  GlobalPlanner all(TspOptions{}, 100);
  EXPECT_EQ(all.plan(hg, robot, [](int32_t) { return false; }).zone_order, plan.zone_order);
}

// Guidance's clusters (Sec. IV-C): those of the first zones of the sequence, and with
// guidance_near_m those within that distance of the robot along G_real, whatever their zone.
TEST(ExplorationPlanner, GuidanceServesTheFirstZonesAndWithGuidanceNearTheRobotsNeighbourhood) {
  ToyGraph t;  // the prior: one room, the target floor's room as observed
  t.add_room({0, 0, 6, 5}, 0.8, 0);
  Harness h;
  HybridGraph hg;
  const uint32_t robot = prior_over_room_a(t, h, hg);
  ASSERT_NE(robot, kNoNode);
  // Two one-node clusters: one within 1.5 m of the robot along G_real, one beyond 4 m.
  GraphSearch search;
  search.dijkstra(hg.search_graph(), std::span<const uint32_t>(&robot, 1), kUnreachable,
                  [&](uint32_t e, uint32_t, uint32_t) { return hg.csr_edge_real(e); });
  storey::core::graph::NodeId near_n = storey::core::graph::kNoId,
                              far_n = storey::core::graph::kNoId;
  for (storey::core::graph::NodeId n = 0; n < h.graph.node_capacity(); ++n) {
    if (!h.graph.node(n).alive) continue;
    const uint32_t u = hg.node_of_real(n);
    if (u == kNoNode) continue;
    const double d = search.dist(u);
    if (d > 0.5 && d < 1.5 && near_n == storey::core::graph::kNoId) near_n = n;
    if (std::isfinite(d) && d > 4.0 && far_n == storey::core::graph::kNoId) far_n = n;
  }
  ASSERT_NE(near_n, storey::core::graph::kNoId);
  ASSERT_NE(far_n, storey::core::graph::kNoId);
  std::vector<storey::core::graph::FrontierCluster> clusters(2);
  clusters[0].id = 1, clusters[0].nodes = {near_n};
  clusters[1].id = 2, clusters[1].nodes = {far_n};
  const std::vector<int32_t> no_zone;
  EXPECT_EQ(guided_clusters(hg, no_zone, robot, 0.0, clusters, search),
            (std::vector<uint8_t>{0, 0}));
  EXPECT_EQ(guided_clusters(hg, no_zone, robot, 3.0, clusters, search),
            (std::vector<uint8_t>{1, 0}));
  const std::vector<int32_t> far_zone{hg.nodes()[hg.node_of_real(far_n)].zone};
  const std::vector<uint8_t> with_zone =
      guided_clusters(hg, far_zone, robot, 0.0, clusters, search);
  EXPECT_EQ(with_zone[1], 1);
}
