#include "core/plan/viewpoint_dp.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace storey::core::plan {

namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();

double wrap_abs(double a) {
  return std::abs(std::remainder(a, 2.0 * M_PI));
}

double travel_dir(const Viewpoint& a, const Viewpoint& b, const ViewpointDpOptions& opt) {
  const double dx = b.p_m.x() - a.p_m.x(), dy = b.p_m.y() - a.p_m.y();
  if (dx * dx + dy * dy < opt.min_step_m * opt.min_step_m) return b.yaw_rad;
  return std::atan2(dy, dx);
}

bool finite_nonneg(double v) {
  return std::isfinite(v) && v >= 0;
}
}  // namespace

const char* to_string(DpStatus s) {
  switch (s) {
    case DpStatus::kOk:
      return "ok";
    case DpStatus::kBadInput:
      return "bad input (empty cluster, no clusters or non-finite pose)";
    case DpStatus::kInfeasible:
      return "infeasible (no candidate sequence with finite distances)";
  }
  return "?";
}

double initial_heading_change(const Viewpoint& x0, const Viewpoint& x1,
                              const ViewpointDpOptions& opt) {
  return wrap_abs(travel_dir(x0, x1, opt) - x0.yaw_rad);
}

double heading_change(const Viewpoint& a, const Viewpoint& b, const Viewpoint& c,
                      const ViewpointDpOptions& opt) {
  const double in = travel_dir(a, b, opt), out = travel_dir(b, c, opt);
  if (opt.heading == HeadingModel::kViaViewpointYaw)
    return wrap_abs(b.yaw_rad - in) + wrap_abs(out - b.yaw_rad);
  return wrap_abs(out - in);
}

WindowCost window_cost(const Viewpoint& x0, std::span<const Viewpoint> seq,
                       const std::optional<Viewpoint>& anchor, const ViewpointDistance& d,
                       const ViewpointDpOptions& opt) {
  WindowCost w;
  if (seq.empty()) return w;
  w.path_m = d(x0, seq[0]);
  w.heading_rad = initial_heading_change(x0, seq[0], opt);
  for (size_t m = 1; m < seq.size(); ++m) {
    w.path_m += d(seq[m - 1], seq[m]);
    w.heading_rad += heading_change(m == 1 ? x0 : seq[m - 2], seq[m - 1], seq[m], opt);
  }
  if (anchor) w.anchor_m = d(seq.back(), *anchor);
  w.total = w.path_m + opt.lambda_psi * w.heading_rad + opt.lambda_a * w.anchor_m;
  return w;
}

DpResult ViewpointDp::solve(const Viewpoint& x0, std::span<const std::vector<Viewpoint>> clusters,
                            const std::optional<Viewpoint>& anchor, const ViewpointDistance& d) {
  DpResult r;
  const int w = std::min<int>(std::max(opt_.window_w, 1), int(clusters.size()));
  if (w == 0 || !x0.p_m.allFinite() || !std::isfinite(x0.yaw_rad)) return r;
  for (int m = 0; m < w; ++m)
    if (clusters[m].empty()) return r;
  auto K = [&](int m) { return int(clusters[m].size()); };
  auto call = [&](const Viewpoint& a, const Viewpoint& b) {
    ++r.distance_calls;
    const double v = d(a, b);
    return finite_nonneg(v) ? v : kInf;  // NaN / negative from the callback: unusable
  };

  // Distance tables: dist_[0][k] = d(x0, X_1^k); dist_[m][a*K_m+b] = d(X_m^a, X_{m+1}^b);
  // dist_[w][k] = d(X_W^k, c_anc).
  dist_.resize(size_t(w) + 1);
  dist_[0].resize(size_t(K(0)));
  for (int k = 0; k < K(0); ++k) dist_[0][k] = call(x0, clusters[0][k]);
  for (int m = 1; m < w; ++m) {
    dist_[m].resize(size_t(K(m - 1)) * K(m));
    for (int a = 0; a < K(m - 1); ++a)
      for (int b = 0; b < K(m); ++b)
        dist_[m][size_t(a) * K(m) + b] = call(clusters[m - 1][a], clusters[m][b]);
  }
  dist_[w].assign(size_t(K(w - 1)), 0.0);
  if (anchor && opt_.lambda_a > 0)
    for (int k = 0; k < K(w - 1); ++k) dist_[w][k] = call(clusters[w - 1][k], *anchor);

  // J over states (previous, current); for the first cluster the previous is x0 (one row).
  j_.assign(size_t(K(0)), kInf);
  for (int b = 0; b < K(0); ++b)
    j_[b] = dist_[0][b] + opt_.lambda_psi * initial_heading_change(x0, clusters[0][b], opt_);
  back_.resize(size_t(w));
  int rows = 1;  // K of the previous cluster (1 for x0)
  for (int m = 1; m < w; ++m) {
    const int kb = K(m - 1), kc = K(m);
    j_next_.assign(size_t(kb) * kc, kInf);
    back_[m].assign(size_t(kb) * kc, -1);
    for (int a = 0; a < rows; ++a) {
      const Viewpoint& pa = m == 1 ? x0 : clusters[m - 2][a];
      for (int b = 0; b < kb; ++b) {
        const double jab = j_[size_t(a) * kb + b];
        if (!std::isfinite(jab)) continue;
        for (int c = 0; c < kc; ++c) {
          const double dbc = dist_[m][size_t(b) * kc + c];
          if (!std::isfinite(dbc)) continue;
          const double v =
              jab + dbc +
              opt_.lambda_psi * heading_change(pa, clusters[m - 1][b], clusters[m][c], opt_);
          double& slot = j_next_[size_t(b) * kc + c];
          if (v < slot) {
            slot = v;
            back_[m][size_t(b) * kc + c] = a;
          }
        }
      }
    }
    j_.swap(j_next_);
    rows = kb;
  }

  // Terminal anchor term, then the best final state.
  const int kl = K(w - 1);
  double best = kInf;
  int best_a = -1, best_b = -1;
  for (int a = 0; a < rows; ++a)
    for (int b = 0; b < kl; ++b) {
      const double v = j_[size_t(a) * kl + b] + opt_.lambda_a * dist_[w][b];
      if (v < best) {
        best = v;
        best_a = a;
        best_b = b;
      }
    }
  if (best_b < 0) {
    r.status = DpStatus::kInfeasible;
    return r;
  }
  r.choice.assign(size_t(w), 0);
  r.choice[w - 1] = best_b;
  if (w >= 2) r.choice[w - 2] = best_a;
  for (int m = w - 1; m >= 2; --m)
    r.choice[m - 2] = back_[m][size_t(r.choice[m - 1]) * K(m) + r.choice[m]];

  // Terms of J from the tables (no further calls of d).
  r.path_m = dist_[0][r.choice[0]];
  r.heading_rad = initial_heading_change(x0, clusters[0][r.choice[0]], opt_);
  for (int m = 1; m < w; ++m) {
    r.path_m += dist_[m][size_t(r.choice[m - 1]) * K(m) + r.choice[m]];
    const Viewpoint& pa = m == 1 ? x0 : clusters[m - 2][r.choice[m - 2]];
    r.heading_rad +=
        heading_change(pa, clusters[m - 1][r.choice[m - 1]], clusters[m][r.choice[m]], opt_);
  }
  r.anchor_m = dist_[w][r.choice[w - 1]];
  r.cost = best;
  r.status = DpStatus::kOk;
  return r;
}

}  // namespace storey::core::plan
