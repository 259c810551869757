#pragma once
// Parameters of the traversability-aware volumetric map (paper Sec. III-A).
namespace storey::core::map {

struct MapOptions {
  double voxel_size_m = 0.1;        // map resolution
  double max_range_m = 30.0;        // rays beyond this are truncated (free space only)
  double min_range_m = 0.3;         // returns closer than this are dropped (robot body)
  float log_odds_hit = 0.85f;       // log-odds added to an endpoint voxel
  float log_odds_miss = -0.4f;      // log-odds added to a voxel a ray passes through
  float log_odds_min = -2.0f;       // clamping
  float log_odds_max = 3.5f;
  float log_odds_occupied = 0.0f;   // occupied above this
  int n_min = 5;                    // N_min, Eq. 3: fewer points -> S_unobs
  double neighbourhood_radius_m = 0.2;  // aggregation radius for Eq. 1
  double w_s = 1.0;                 // w_s, Eq. 2 slope weight
  double w_r = 0.5;                 // w_r, Eq. 2 roughness weight
  double w_u = 0.3;                 // w_u, Eq. 2 under-observation weight
  double tau_c = 0.8;               // tau_c, Eq. 3 maximum terrain cost
};

}  // namespace storey::core::map
