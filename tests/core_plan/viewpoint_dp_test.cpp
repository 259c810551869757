#include "core/plan/viewpoint_dp.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <random>
#include <vector>

namespace storey::core::plan {
namespace {

double euclid(const Viewpoint& a, const Viewpoint& b) {
  return (a.p_m - b.p_m).norm();
}

// Exhaustive search over every combination of candidates in the window.
double brute_force(const Viewpoint& x0, const std::vector<std::vector<Viewpoint>>& cl, int w,
                   const std::optional<Viewpoint>& anc, const ViewpointDistance& d,
                   const ViewpointDpOptions& opt, std::vector<int>* best_idx) {
  double best = std::numeric_limits<double>::infinity();
  std::vector<int> idx(size_t(w), 0);
  while (true) {
    std::vector<Viewpoint> seq;
    for (int m = 0; m < w; ++m) seq.push_back(cl[m][idx[m]]);
    const double v = window_cost(x0, seq, anc, d, opt).total;
    if (v < best) {
      best = v;
      *best_idx = idx;
    }
    int m = w - 1;
    while (m >= 0 && ++idx[m] == int(cl[m].size())) idx[m--] = 0;
    if (m < 0) break;
  }
  return best;
}

TEST(ViewpointDp, MatchesBruteForceOnRandomWindows) {
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> u(-10, 10), yaw(-M_PI, M_PI), lam(0, 2);
  for (int trial = 0; trial < 150; ++trial) {
    ViewpointDpOptions opt;
    opt.window_w = 1 + trial % 5;
    opt.lambda_psi = lam(rng);
    opt.lambda_a = trial % 3 == 0 ? 0.0 : lam(rng);
    opt.heading = trial % 2 ? HeadingModel::kViaViewpointYaw : HeadingModel::kTravelDirection;
    const int m_clusters = opt.window_w + trial % 2;  // sometimes more clusters than W
    std::vector<std::vector<Viewpoint>> cl(static_cast<size_t>(m_clusters));
    for (auto& c : cl) {
      const int k = 1 + int(rng() % 4);
      for (int i = 0; i < k; ++i) c.push_back({{u(rng), u(rng), 0}, yaw(rng)});
    }
    const Viewpoint x0{{u(rng), u(rng), 0}, yaw(rng)};
    std::optional<Viewpoint> anc;
    if (trial % 4 != 1) anc = Viewpoint{{u(rng), u(rng), 0}, 0};
    // Asymmetric, non-Euclidean "path costs" (detours) to exercise the tables.
    auto d = [](const Viewpoint& a, const Viewpoint& b) {
      return euclid(a, b) * (1.0 + 0.3 * std::abs(std::sin(a.p_m.x() + 2 * b.p_m.y())));
    };
    ViewpointDp dp(opt);
    const DpResult r = dp.solve(x0, cl, anc, d);
    ASSERT_EQ(r.status, DpStatus::kOk);
    const int w = std::min(opt.window_w, m_clusters);
    ASSERT_EQ(int(r.choice.size()), w);
    std::vector<int> bf_idx;
    const double bf = brute_force(x0, cl, w, anc, d, opt, &bf_idx);
    EXPECT_NEAR(r.cost, bf, 1e-9) << "trial " << trial;
    // The reported terms add up to J and agree with an independent evaluation of the choice.
    std::vector<Viewpoint> seq;
    for (int m = 0; m < w; ++m) seq.push_back(cl[m][r.choice[m]]);
    const WindowCost wc = window_cost(x0, seq, opt.lambda_a > 0 ? anc : std::nullopt, d, opt);
    EXPECT_NEAR(wc.total, r.cost, 1e-9);
    EXPECT_NEAR(r.path_m, wc.path_m, 1e-9);
    EXPECT_NEAR(r.heading_rad, wc.heading_rad, 1e-9);
    // O(W K^2) distance calls, not K^W.
    EXPECT_LE(r.distance_calls, uint32_t(4 + 16 * (w - 1) + 4));
  }
}

TEST(ViewpointDp, FewerHeadingChangesWinWhenPathLengthsTie) {
  // Robot at the origin facing +x. Each cluster offers a candidate on the x axis and one off it.
  // A constant d makes every sequence's path length equal; only heading changes differ.
  std::vector<std::vector<Viewpoint>> cl;
  for (int m = 1; m <= 4; ++m)
    cl.push_back({{{double(m), 1.5 * ((m % 2) ? 1 : -1), 0}, 0}, {{double(m), 0, 0}, 0}});
  const Viewpoint x0{{0, 0, 0}, 0};
  auto d = [](const Viewpoint&, const Viewpoint&) { return 2.0; };
  ViewpointDpOptions opt;
  opt.lambda_psi = 0.5;
  ViewpointDp dp(opt);
  const DpResult r = dp.solve(x0, cl, std::nullopt, d);
  ASSERT_EQ(r.status, DpStatus::kOk);
  EXPECT_EQ(r.choice, (std::vector<int>{1, 1, 1, 1}));  // straight along +x
  EXPECT_NEAR(r.heading_rad, 0.0, 1e-12);
  EXPECT_NEAR(r.path_m, 8.0, 1e-12);
  // Facing -x instead, the first move costs a half turn whatever is chosen, the rest stays 0.
  const DpResult r2 = dp.solve(Viewpoint{{0, 0, 0}, M_PI}, cl, std::nullopt, d);
  EXPECT_EQ(r2.choice, (std::vector<int>{1, 1, 1, 1}));
  EXPECT_NEAR(r2.heading_rad, M_PI, 1e-9);
}

TEST(ViewpointDp, AnchorPullsTheLastViewpoint) {
  // One cluster with two equal-cost candidates; the anchor decides.
  std::vector<std::vector<Viewpoint>> cl{{{{2, 1, 0}, 0}, {{2, -1, 0}, 0}}};
  const Viewpoint x0{{0, 0, 0}, 0};
  ViewpointDpOptions opt;
  opt.lambda_a = 1.0;
  ViewpointDp dp(opt);
  const DpResult r = dp.solve(x0, cl, Viewpoint{{5, -4, 0}, 0}, euclid);
  ASSERT_EQ(r.status, DpStatus::kOk);
  EXPECT_EQ(r.choice[0], 1);
  EXPECT_GT(r.anchor_m, 0);
}

TEST(ViewpointDp, UnreachableCandidatesAndBadInput) {
  const Viewpoint x0{{0, 0, 0}, 0};
  std::vector<std::vector<Viewpoint>> cl{{{{1, 0, 0}, 0}, {{0, 1, 0}, 0}}, {{{2, 0, 0}, 0}}};
  // The straight candidate of cluster 1 is unreachable (+inf), so the other one is chosen.
  auto d = [](const Viewpoint& a, const Viewpoint& b) {
    if (b.p_m.x() == 1) return std::numeric_limits<double>::infinity();
    return euclid(a, b);
  };
  ViewpointDp dp;
  const DpResult r = dp.solve(x0, cl, std::nullopt, d);
  ASSERT_EQ(r.status, DpStatus::kOk);
  EXPECT_EQ(r.choice, (std::vector<int>{1, 0}));
  auto none = [](const Viewpoint&, const Viewpoint&) { return std::nan(""); };
  EXPECT_EQ(dp.solve(x0, cl, std::nullopt, none).status, DpStatus::kInfeasible);
  std::vector<std::vector<Viewpoint>> empty_cluster{{}, {{{1, 0, 0}, 0}}};
  EXPECT_EQ(dp.solve(x0, empty_cluster, std::nullopt, d).status, DpStatus::kBadInput);
  EXPECT_EQ(dp.solve(x0, {}, std::nullopt, d).status, DpStatus::kBadInput);
  EXPECT_EQ(dp.solve(Viewpoint{{std::nan(""), 0, 0}, 0}, cl, std::nullopt, d).status,
            DpStatus::kBadInput);
}

TEST(ViewpointDp, HeadingDefinition) {
  ViewpointDpOptions opt;
  const Viewpoint a{{0, 0, 0}, 0}, b{{1, 0, 0}, M_PI / 2}, c{{1, 1, 0}, 0}, d{{0, 0, 0}, 0};
  EXPECT_NEAR(heading_change(a, b, c, opt), M_PI / 2, 1e-12);  // left turn at b
  EXPECT_NEAR(heading_change(a, b, d, opt), M_PI, 1e-12);      // U-turn
  EXPECT_NEAR(initial_heading_change(Viewpoint{{0, 0, 0}, -M_PI / 2}, b, opt), M_PI / 2, 1e-12);
  opt.heading = HeadingModel::kViaViewpointYaw;                // turn to face b's yaw first
  EXPECT_NEAR(heading_change(a, b, c, opt), M_PI / 2, 1e-12);  // 90 to yaw, 0 onward
  const Viewpoint b2{{1, 0, 0}, -M_PI / 2};
  EXPECT_NEAR(heading_change(a, b2, c, opt), 1.5 * M_PI, 1e-12);  // right 90, then left 180
  // Coincident waypoints take the arrival yaw as direction: no spurious turn.
  opt.heading = HeadingModel::kTravelDirection;
  const Viewpoint a2{{1, 0, 0}, 0};
  EXPECT_NEAR(initial_heading_change(Viewpoint{{1, 0, 0}, 0}, a2, opt), 0.0, 1e-12);
}

}  // namespace
}  // namespace storey::core::plan
