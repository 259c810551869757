#pragma once
// Parameters of the traversability-aware volumetric map (paper Sec. III-A).
// Units are in every name; paper symbols in the comments.
namespace storey::core::map {

struct MapOptions {
  // Beyond the paper, on in config/default.yaml (issue #9, set by plan.climb_blind): a riser's
  // short top piece is judged with the riser below it (riser_plane), and a sheet over observed open
  // air is a ledge, not a step.
  bool pool_short_risers = false;
  // Beyond the paper, on in config/default.yaml (set by plan.climb_blind): the C_reach seed prefers
  // the support under the body at the feet's level to C_reach members (a landing reached by a blind
  // climb).
  bool seed_under_feet = false;
  // Beyond the paper, on in config/default.yaml (issue #9, map.spill_is_surface): a voxel under
  // N_min low over a level, well-observed floor is that floor's spill across a voxel boundary,
  // judged as a surface.
  bool spill_is_surface = false;
  // Beyond the paper (map.miss_needs_crossing): a ray counts against an occupied voxel whose points
  // lie on a plane only if it crosses that plane inside the voxel. Rays down a corridor pass a few
  // centimetres in front of its walls, within the points' spread, and freed the walls seen from
  // afar; C_exp probes then left through them and frontiers came and went with the robot's
  // distance (test_ramp seed 1, session 22).
  bool miss_needs_crossing = false;
  // Beyond the paper, off in config/default.yaml (map.floor_seen_from_above, session 31: on, house
  // seed 1's path changed and met a body collision): a top surface needs a point seen from above it
  // (a ray rising less steeply than the surface's slope). A ceiling seen from the floor below, its
  // slab's inside never observed, read as a floor over the whole building (teaching_building seed
  // 1 with a 0.3 rad yaw gate: 1,473 graph nodes on the 3.0 m underside of the 3.2 m floor, every
  // cluster there unreachable, and "complete" on the upper floor at 2.5 %). A step edge (a riser's
  // top seen from below, the tread behind it inferred) is exempt. With it, graph::SupportQuery
  // marks such a surface an underside and Eq. 5 counts it missing (session 34: test_ramp seed 4's
  // upper corridors, seen only from below, then hold C_sur frontiers; the teaching building's
  // upper floor was then never reached).
  bool floor_seen_from_above = false;
  // --- occupancy (ray casting) ---
  double voxel_size_m = 0.1;    // map resolution
  double max_range_m = 30.0;    // rays beyond this are truncated (free space only, no endpoint)
  double min_range_m = 0.3;     // returns closer than this are dropped (robot body)
  float log_odds_hit = 0.85f;   // log-odds added to an endpoint voxel (once per scan)
  float log_odds_miss = -0.4f;  // log-odds added to a voxel a ray passes through (once per scan)
  float log_odds_min = -2.0f;   // clamping (keeps the map able to change)
  float log_odds_max = 3.5f;
  float log_odds_occupied = 0.0f;  // occupied above this
  int ray_early_stop_voxels = 4;   // rays are cast from the endpoint back to the sensor and
                                   // stop after this many consecutive voxels already updated
                                   // in this scan (near the sensor every ray overlaps the
                                   // others; voxblox's "fast" integrator). 0: exact, every
                                   // voxel of every ray.
  // --- terrain statistics, Eq. 1-3 ---
  int n_min = 5;                        // N_min, Eq. 3: fewer points in v -> S_unobs
  double neighbourhood_radius_m = 0.2;  // aggregation radius for Eq. 1 (horizontal)
  double neighbourhood_dz_m = 0.1;      // aggregation keeps support voxels within this height of v
                                        // (so stair treads are not blended with the next tread)
  int n_ref = 40;                       // u(v) = 1 - min(1, N_agg / n_ref): under-observation
  double w_s = 1.0;                     // w_s, Eq. 2 slope weight (s_bar = s / max_slope)
  double w_r = 0.5;                     // w_r, Eq. 2 roughness weight (r_bar = r, already in [0,1])
  double w_u = 0.3;                     // w_u, Eq. 2 under-observation weight (u_bar = u)
  double tau_c = 1.0;                // tau_c, Eq. 3 maximum terrain cost; 1.0 so that slope alone
                                     // reaches it exactly at RobotModel::max_slope_rad
  double fall_support_ratio = 0.75;  // R_fall: more than (1 - this) of the neighbour columns
                                     // within neighbourhood_radius_m are observed drops -> fall
  double collision_radius_m = 0.1;   // R_col: horizontal radius of the clearance column above v
  // --- reachable set ---
  double seed_search_radius_m = 1.0;  // robot support voxel: nearest traversable within this
                                      // (the LiDAR cannot see under the body, min_range_m)
  // --- limits (bad input) ---
  double world_limit_m = 100000.0;  // points/origins with |coordinate| beyond this are dropped
};

}  // namespace storey::core::map
