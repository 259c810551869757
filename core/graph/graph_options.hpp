#pragma once
// Parameters of the incremental reachable graph and topological frontiers (paper III-B, III-C).
// Units in every name; paper symbols in the comments. Robot geometry (step height, body height,
// width, margin) comes from core::RobotModel.
#include <cstdint>

namespace storey::core::graph {

struct GraphOptions {
  double r_e_m = 1.0;             // r_e, Eq. 4 expansion radius
  double node_clearance_m = 0.5;  // minimum distance between nodes (reuse existing)
  int k_max = 8;                  // k_max, maximum node degree (<= ReachableGraph::kMaxDegree)
  double alpha_min_rad = 0.5235987755982988;  // alpha_min, 30 deg edge angular separation
  int expansion_samples = 12;                 // candidates theta ~ U(0, 2pi) per node and update
  double rho_min = 0.3;                       // rho_min, Eq. 5 missing-surface ratio threshold
  double surface_radius_factor = 1.0;         // radius of Omega_i = factor * r_e
  int probes = 12;                            // radial probes for C_exp
  int theta_min = 2;                          // Theta_min, open directions for C_exp
  // Beyond the paper, on in config/default.yaml (issue #9, set by plan.climb_blind): one open probe
  // that climbed two stair steps satisfies C_exp (a flight is one probe wide), and a probe follows
  // a flight to its top.
  bool climb_frontiers = false;
  // Beyond the paper, on in config/default.yaml (issue #9, graph.close_probes_at_holes): a C_exp
  // probe entering unknown space through a voxel-sized gap in a surface (a wall seen at grazing
  // angles) is closed.
  bool close_probes_at_holes = false;
  // Beyond the paper, on in config/default.yaml since session 33 (graph.close_probes_at_wall_faces,
  // session 25): a C_exp probe that meets a wall's face where a voxel of it has free space over it
  // takes no "step" there (the wall rises on behind it, SupportQuery::wall_face); off, such a
  // voxel seen edge-on is a tread.
  bool close_probes_at_wall_faces = false;
  // Beyond the paper, off (graph.passage_frontiers, sessions 26, 28): C_exp also holds for an
  // open probe whose two neighbours are both blocked by obstacles (passage_probes): a corridor or
  // door one probe wide, the level analogue of the flight rule (climb_frontiers). With
  // close_probes_at_wall_faces a corridor's end had one open probe only (Theta_min = 2) and
  // test_ramp's upper corridors were left unexplored.
  bool passage_frontiers = false;
  // Beyond the paper, off (graph.ramp_frontiers, session 29; acts with climb_frontiers): the
  // flight rule for ramps: one open probe whose support rose a step height on the way, in climbs
  // flatter than a stair's (a curb is no ramp), satisfies C_exp. A ramp 1.5 m wide is one probe
  // wide too (30 deg apart), and the graph's end on it, seen only from its foot, had one open probe
  // up it (Theta_min = 2): test_ramp seed 4 with plan.start_at_speed was "complete" with the upper
  // floor at 2.4 %.
  bool ramp_frontiers = false;
  double probe_length_m = 3.0;      // probe length for C_exp
  int cluster_capacity = 8;         // maximum frontier nodes per cluster
  int viewpoints_per_cluster = 8;   // K, best viewpoints kept per cluster
  double viewpoint_radius_m = 2.5;  // candidate viewpoints from nodes within this radius
  // Ablation switches (paper Table III).
  bool use_tentative = true;        // false: "w/o tentative", graph restricted to C_reach
  bool use_c_sur = true;            // false: "w/o surface criterion"
  bool use_c_exp = true;            // false: "w/o expansion criterion"
  bool boundary_frontiers = false;  // true: frontiers from the geometric boundary of C_reach

  // --- graph geometry (Sec. III-B) ---
  double neighbour_radius_factor = 1.6;  // a new node also links to nodes within factor * r_e
  double max_edge_slope_rad = 0.6981317007977318;  // 40 deg: mean grade of an edge (stairs of
                                                   // 0.17/0.28 m are ~31 deg)
  double max_gap_m = 0.35;            // tentative edges may cross unknown (never observed) ground
                                      // for at most this long (a sparsely observed gap)
  double surface_tolerance_m = 0.03;  // slack on the step height for surface noise
  double root_radius_m = 1.0;         // the robot's node: nearest within this, else a new one
  // Beyond the paper, on in config/default.yaml (set by plan.climb_blind). The robot's node where
  // the nearest one lies more than half a step below or above it and farther than node_clearance_m:
  // a new node on the support under the feet. A robot that climbed a flight blind
  // (PlanOptions::climb_blind) stands on a landing G_real never reached, and the flight's top node
  // is no place to grow the new floor's graph from.
  bool root_off_graph = false;
  double floor_height_hint_m = 3.0;  // floor id hint = round(z / this) (planning refines floors)
  // A cut that leaves the robot in the smaller part is more likely a transient (a node near the
  // robot lost and not yet re-linked) than a real one: the larger part is kept this many updates
  // before it is pruned (a real cut, e.g. a closed door, still prunes it after the window).
  int prune_persistence_updates = 30;
  // Beyond the paper, off (graph.keep_reachable_cut; session 12): nodes cut off from the robot in
  // G_real whose support is still in C_reach (grown from the robot over the map's voxels) are
  // kept, not pruned: a cut of the graph, not of the terrain. Maze's 1.5 m ramp holds a chain one
  // node wide; revalidation near its walls cut it with the robot on the short side, and the
  // ground floor's graph, with every frontier on it, was pruned and never regrew. Expansion can
  // re-link the parts, but nothing makes it: in the office (seed 2) a part that stayed cut held
  // the floor's last cluster, unreachable, and the run ended "complete" at 58 s with 27 % seen.
  bool keep_reachable_cut = false;
  // Beyond the paper, off (graph.relink_cuts; session 20): what keep_reachable_cut keeps, nothing
  // re-links. Office seed 3 (with plan.replan_only_if_faster): the robot walked through a door,
  // the one edge through it was pruned (the frame seen at close range inside its clearance), the
  // room and the rest stayed two components and the run ended "complete" at 85.5 s with 48.6 %
  // seen. Each second, while real nodes lie outside the robot's component, the closest pairs
  // across the cut (within neighbour_radius_factor * r_e) are tried as edges, the alpha_min
  // spacing rule waived (a bridge is worth a crowded fan), at most relink_tries per second.
  bool relink_cuts = false;
  int relink_tries = 16;
  // Beyond the paper (graph.surface_seen_from_above; session 18). Eq. 5's I(x, z_i) counts a
  // support surface only if a ray has crossed the voxel above it, or the one above that: the
  // underside of the floor above, seen from below, has the same "occupied with nothing occupied
  // above" shape as a floor within a step of a node on the upper floor. test_ramp seed 2: the
  // upper floor's two side strips, never seen from above, held no frontier (rho 0.04) and the run
  // ended "complete" with that floor at 32 %.
  bool surface_seen_from_above = false;
  // --- incremental update budgets (bounded work per map cycle) ---
  // (~23 us per operation at 0.1 m voxels: these bound a cycle to ~5 ms CPU; PERFORMANCE.md)
  int max_expansions_per_update = 40;     // nodes expanded per update (queue carries over)
  int max_revalidations_per_update = 80;  // nodes (with their edges) re-checked per update
  int max_frontier_updates = 80;          // nodes whose frontier flags are recomputed per update
  // --- frontiers (Sec. III-C) ---
  int surface_samples = 32;        // |Omega_i|: samples of the disc, Eq. 5
  double probe_height_m = 0.3;     // C_exp probes run this far above the node's support
  double probe_unknown_m = 0.3;    // C_exp: a probe is open if its last this-many metres are
                                   // unknown (it ends in an unknown region, not a hole)
  double boundary_radius_m = 0.5;  // boundary ablation: C_reach boundary voxels this close
  // --- viewpoints (Sec. III-C, last paragraph) ---
  double viewpoint_target_height_m = 0.15;  // rays aim this far above a frontier node's support
};

}  // namespace storey::core::graph
