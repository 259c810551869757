#pragma once
// Parameters of hierarchical planning with cross-floor priors (paper Sec. IV).
namespace storey::core::plan {

struct PlanOptions {
  double r_z_m = 6.0;                 // r_z, bounded Dijkstra radius of a task zone
  int min_zone_nodes = 4;             // zones smaller than this are absorbed into neighbours
  int zone_capacity = 60;             // node capacity when merging unassigned components
  int window_w = 4;                   // W, DP window (Eq. 6)
  int max_candidates_k = 8;           // K, viewpoints per cluster in the DP
  double lambda_psi = 0.5;            // lambda_psi, Eq. 6 heading-change penalty [m/rad]
  double lambda_a = 0.5;              // lambda_a, Eq. 6 anchor-distance weight
  int guidance_zones = 2;             // clusters from the first few zones of the global sequence
  double floor_change_dz_m = 1.5;     // support height change that means another floor
  int hyp_discard_observations = 3;   // repeated empty observations before discarding S_hyp
  double hyp_promote_radius_m = 0.5;  // support found this close to a hypothetical column
  // Ablation switches (paper Table IV).
  bool use_prior = true;
  bool incremental_maintenance = true;
};

}  // namespace storey::core::plan
