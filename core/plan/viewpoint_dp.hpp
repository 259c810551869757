#pragma once
// Stage 2 of local planning (paper Sec. IV-D, Eq. 6): along the cluster sequence from Stage 1,
// choose one viewpoint per cluster inside a window of W clusters minimising
//
//   J = d(x0, x1) + sum_{m=1}^{W-1} d(x_m, x_{m+1}) + lambda_psi * sum_{m=0}^{W-1} dpsi_m
//       + lambda_a * d(x_W, c_anc)
//
// d(.,.) is the A* path cost on the sparse graph, supplied by the caller. Heading change dpsi_m
// (paper: "evaluating dpsi_m requires three consecutive waypoints"): with dir(a, b) the
// horizontal travel direction atan2(b.y - a.y, b.x - a.x) (for a horizontal step shorter than
// min_step_m: the yaw of b, so coincident waypoints cost no spurious turn),
//   dpsi_0 = |wrap(dir(x0, x1) - psi0)|                         psi0 = the robot's current yaw
//   dpsi_m = |wrap(dir(x_m, x_{m+1}) - dir(x_{m-1}, x_m))|        m = 1 .. W-1
// i.e. the turn at x_m between the incoming and the outgoing travel direction. With
// HeadingModel::kViaViewpointYaw the robot also turns to the viewpoint's yaw psi_m at x_m:
//   dpsi_m = |wrap(psi_m - dir(x_{m-1}, x_m))| + |wrap(dir(x_m, x_{m+1}) - psi_m)|.
// DP state = the last two chosen viewpoints, so the solve is O(W K^3) with O(W K^2) calls of d.
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <vector>

#include <Eigen/Core>

namespace storey::core::plan {

struct Viewpoint {
  Eigen::Vector3d p_m = Eigen::Vector3d::Zero();  // position on the support surface [m]
  double yaw_rad = 0;                             // facing the cluster centroid (Sec. III-C)
  uint32_t node = 0xFFFFFFFFu;                    // graph node id for d(.,.), or none
};

enum class HeadingModel : uint8_t {
  kTravelDirection = 0,  // turn between incoming and outgoing travel direction (default)
  kViaViewpointYaw = 1,  // ... passing through the viewpoint's own yaw
};

struct ViewpointDpOptions {
  int window_w = 4;         // W
  double lambda_psi = 0.5;  // lambda_psi [m/rad]
  double lambda_a = 0.5;    // lambda_a
  HeadingModel heading = HeadingModel::kTravelDirection;
  double min_step_m = 1e-3;  // shorter horizontal steps take the arrival viewpoint's yaw as dir
};

// d(a, b) >= 0, +inf when b is unreachable from a.
using ViewpointDistance = std::function<double(const Viewpoint&, const Viewpoint&)>;

enum class DpStatus : uint8_t { kOk = 0, kBadInput, kInfeasible };
const char* to_string(DpStatus s);

struct DpResult {
  DpStatus status = DpStatus::kBadInput;
  std::vector<int> choice;  // candidate index per cluster of the window (size = min(W, M))
  double cost = 0;          // J
  double path_m = 0;        // sum of d terms
  double heading_rad = 0;   // sum of dpsi_m
  double anchor_m = 0;      // d(x_W, c_anc) (0 without anchor)
  uint32_t distance_calls = 0;
};

// The terms of J for a given sequence (also used by tests as the brute-force reference).
struct WindowCost {
  double path_m = 0, heading_rad = 0, anchor_m = 0, total = 0;
};
WindowCost window_cost(const Viewpoint& x0, std::span<const Viewpoint> seq,
                       const std::optional<Viewpoint>& anchor, const ViewpointDistance& d,
                       const ViewpointDpOptions& opt);

// dpsi at b for the waypoints a -> b -> c under `opt.heading`.
double heading_change(const Viewpoint& a, const Viewpoint& b, const Viewpoint& c,
                      const ViewpointDpOptions& opt);
// dpsi_0: from the robot's yaw at x0 to the first travel direction.
double initial_heading_change(const Viewpoint& x0, const Viewpoint& x1,
                              const ViewpointDpOptions& opt);

class ViewpointDp {
 public:
  explicit ViewpointDp(const ViewpointDpOptions& options = {}) : opt_(options) {}

  // clusters[m] = candidates X_m of the m-th cluster in Stage-1 order; only the first W are used.
  DpResult solve(const Viewpoint& x0, std::span<const std::vector<Viewpoint>> clusters,
                 const std::optional<Viewpoint>& anchor, const ViewpointDistance& d);

  const ViewpointDpOptions& options() const { return opt_; }

 private:
  ViewpointDpOptions opt_;
  // Scratch (reused): distances between consecutive clusters, DP values and back pointers.
  std::vector<std::vector<double>> dist_;
  std::vector<double> j_, j_next_;
  std::vector<std::vector<int>> back_;
};

}  // namespace storey::core::plan
