#pragma once
// Parameters of the incremental reachable graph and topological frontiers (paper III-B, III-C).
namespace storey::core::graph {

struct GraphOptions {
  double r_e_m = 1.0;                  // r_e, Eq. 4 expansion radius
  double node_clearance_m = 0.5;       // minimum distance between nodes (reuse existing)
  int k_max = 8;                       // k_max, maximum node degree
  double alpha_min_rad = 0.5235987755982988;  // alpha_min, 30 deg edge angular separation
  int expansion_samples = 12;          // candidates theta ~ U(0, 2pi) per node and update
  double rho_min = 0.3;                // rho_min, Eq. 5 missing-surface ratio threshold
  double surface_radius_factor = 1.0;  // radius of Omega_i = factor * r_e
  int probes = 12;                     // radial probes for C_exp
  int theta_min = 2;                   // Theta_min, open directions for C_exp
  double probe_length_m = 3.0;         // probe length for C_exp
  int cluster_capacity = 8;            // maximum frontier nodes per cluster
  int viewpoints_per_cluster = 8;      // K, best viewpoints kept per cluster
  double viewpoint_radius_m = 2.5;     // candidate viewpoints from nodes within this radius
  // Ablation switches (paper Table III).
  bool use_tentative = true;
  bool use_c_sur = true;
  bool use_c_exp = true;
  bool boundary_frontiers = false;
};

}  // namespace storey::core::graph
