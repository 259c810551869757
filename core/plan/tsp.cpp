#include "core/plan/tsp.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace storey::core::plan {

namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr int kExactHardCap = 16;  // 2^15 * 15 doubles = 3.9 MB: beyond that always heuristic

// Accept a local-search move only if it gains more than this (relative), so ties and rounding
// never make the search cycle.
bool gains(double delta, double cost) {
  return delta < -1e-9 * (1.0 + std::abs(cost));
}
}  // namespace

const char* to_string(TspStatus s) {
  switch (s) {
    case TspStatus::kOk:
      return "ok";
    case TspStatus::kBadInput:
      return "bad input";
    case TspStatus::kInfeasible:
      return "infeasible (every tour has an infinite leg)";
  }
  return "?";
}

double path_cost(const CostMatrix& m, std::span<const int> order) {
  double c = 0;
  for (size_t i = 1; i < order.size(); ++i) c += m(order[i - 1], order[i]);
  return c;
}

TspStatus TspSolver::validate(const CostMatrix& m, int start, int end) const {
  if (m.n <= 0 || m.c.size() != size_t(m.n) * size_t(m.n)) return TspStatus::kBadInput;
  if (start < 0 || start >= m.n || end < -1 || end >= m.n) return TspStatus::kBadInput;
  if (end == start && m.n > 1) return TspStatus::kBadInput;
  for (int i = 0; i < m.n; ++i)
    for (int j = 0; j < m.n; ++j) {
      if (i == j) continue;
      const double v = m(i, j);
      if (std::isnan(v) || v < 0) return TspStatus::kBadInput;
    }
  return TspStatus::kOk;
}

TspResult TspSolver::solve(const CostMatrix& m, int start, int end) {
  if (m.n <= std::min(opt_.exact_max_n, kExactHardCap)) return solve_exact(m, start, end);
  return solve_heuristic(m, start, end);
}

TspResult TspSolver::solve_exact(const CostMatrix& m, int start, int end) {
  TspResult r;
  r.status = validate(m, start, end);
  if (r.status != TspStatus::kOk) return r;
  if (m.n > kExactHardCap) {
    r.status = TspStatus::kBadInput;
    return r;
  }
  r.exact = true;
  if (m.n == 1) {
    r.order = {start};
    return r;
  }
  // Held-Karp over the free nodes (all but start and the fixed end): dp[mask][j] = cheapest path
  // from start through exactly `mask`, ending at free node j in mask.
  nodes_.clear();
  for (int i = 0; i < m.n; ++i)
    if (i != start && i != end) nodes_.push_back(i);
  const int k = int(nodes_.size());
  if (k == 0) {  // n == 2 with a fixed end
    r.order = {start, end};
    r.cost = m(start, end);
    r.status = std::isfinite(r.cost) ? TspStatus::kOk : TspStatus::kInfeasible;
    return r;
  }
  const size_t states = size_t(1) << k;
  dp_.assign(states * size_t(k), kInf);
  parent_.assign(states * size_t(k), -1);
  for (int j = 0; j < k; ++j) dp_[(size_t(1) << j) * k + j] = m(start, nodes_[j]);
  for (size_t mask = 1; mask < states; ++mask) {
    for (int j = 0; j < k; ++j) {
      if (!(mask & (size_t(1) << j))) continue;
      const double base = dp_[mask * k + j];
      if (!std::isfinite(base)) continue;
      for (int q = 0; q < k; ++q) {
        if (mask & (size_t(1) << q)) continue;
        const size_t nm = mask | (size_t(1) << q);
        const double v = base + m(nodes_[j], nodes_[q]);
        if (v < dp_[nm * k + q]) {
          dp_[nm * k + q] = v;
          parent_[nm * k + q] = int8_t(j);
        }
      }
    }
  }
  const size_t full = states - 1;
  double best = kInf;
  int last = -1;
  for (int j = 0; j < k; ++j) {
    const double v = dp_[full * k + j] + (end >= 0 ? m(nodes_[j], end) : 0.0);
    if (v < best) {
      best = v;
      last = j;
    }
  }
  if (last < 0) {  // every completion infinite: report the identity order as best effort
    r.status = TspStatus::kInfeasible;
    r.order.push_back(start);
    r.order.insert(r.order.end(), nodes_.begin(), nodes_.end());
    if (end >= 0) r.order.push_back(end);
    r.cost = kInf;
    return r;
  }
  std::vector<int> rev;
  size_t mask = full;
  for (int j = last; j >= 0;) {
    rev.push_back(nodes_[j]);
    const int p = parent_[mask * k + j];
    mask &= ~(size_t(1) << j);
    j = p;
  }
  r.order.push_back(start);
  r.order.insert(r.order.end(), rev.rbegin(), rev.rend());
  if (end >= 0) r.order.push_back(end);
  r.cost = path_cost(m, r.order);
  return r;
}

TspResult TspSolver::solve_heuristic(const CostMatrix& m_in, int start, int end) {
  TspResult r;
  r.status = validate(m_in, start, end);
  if (r.status != TspStatus::kOk) return r;
  const int n = m_in.n;
  // Work on a copy where +inf is a large finite penalty, so insertion deltas stay defined.
  double max_finite = 0;
  for (double v : m_in.c)
    if (std::isfinite(v)) max_finite = std::max(max_finite, v);
  const double big = 1e3 * (1.0 + double(n) * max_finite);
  dp_.resize(m_in.c.size());
  for (size_t i = 0; i < m_in.c.size(); ++i) dp_[i] = std::isfinite(m_in.c[i]) ? m_in.c[i] : big;
  const CostMatrix m{n, dp_};

  // Cheapest insertion: repeatedly insert the (node, position) pair with the least increase.
  std::vector<int> tour{start};
  if (end >= 0) tour.push_back(end);
  std::vector<char> in(size_t(n), 0);
  in[size_t(start)] = 1;
  if (end >= 0) in[size_t(end)] = 1;
  for (int added = int(tour.size()); added < n; ++added) {
    double best = kInf;
    int best_node = -1;
    size_t best_pos = 0;  // insert before tour[best_pos]; tour.size() = append
    for (int v = 0; v < n; ++v) {
      if (in[size_t(v)]) continue;
      for (size_t p = 1; p <= tour.size(); ++p) {
        double d;
        if (p < tour.size())
          d = m(tour[p - 1], v) + m(v, tour[p]) - m(tour[p - 1], tour[p]);
        else if (end < 0)
          d = m(tour.back(), v);
        else
          continue;  // nothing may follow the fixed end
        if (d < best) {
          best = d;
          best_node = v;
          best_pos = p;
        }
      }
    }
    tour.insert(tour.begin() + std::ptrdiff_t(best_pos), best_node);
    in[size_t(best_node)] = 1;
  }
  improve(m, tour, end >= 0);

  // Second construction, nearest neighbour, improved the same way; keep the cheaper (local search
  // from two different starts escapes many of the 2-opt/Or-opt local minima, deterministically).
  std::vector<int> nn{start};
  std::fill(in.begin(), in.end(), 0);
  in[size_t(start)] = 1;
  if (end >= 0) in[size_t(end)] = 1;
  for (int added = end >= 0 ? 2 : 1; added < n; ++added) {
    int best_node = -1;
    double best = kInf;
    for (int v = 0; v < n; ++v)
      if (!in[size_t(v)] && m(nn.back(), v) < best) {
        best = m(nn.back(), v);
        best_node = v;
      }
    nn.push_back(best_node);
    in[size_t(best_node)] = 1;
  }
  if (end >= 0) nn.push_back(end);
  improve(m, nn, end >= 0);
  if (path_cost(m, nn) < path_cost(m, tour)) tour.swap(nn);

  r.order = std::move(tour);
  r.cost = path_cost(m_in, r.order);
  r.status = std::isfinite(r.cost) ? TspStatus::kOk : TspStatus::kInfeasible;
  return r;
}

// 2-opt (segment reversal, O(1) deltas for asymmetric costs via forward/backward prefix sums)
// and Or-opt (move a run of 1-3 nodes elsewhere, optionally reversed), first improvement, until
// no move gains or the round limit is hit. tour[0] never moves; the last node stays if fixed.
void TspSolver::improve(const CostMatrix& m, std::vector<int>& t, bool fixed_end) {
  const int n = int(t.size());
  if (n < 3) return;
  const int last_movable = fixed_end ? n - 2 : n - 1;
  std::vector<double> fwd(size_t(n), 0), bwd(size_t(n), 0);
  std::vector<int> buf;
  buf.reserve(size_t(n));
  auto prefix = [&] {
    for (int q = 1; q < n; ++q) {
      fwd[size_t(q)] = fwd[size_t(q - 1)] + m(t[q - 1], t[q]);
      bwd[size_t(q)] = bwd[size_t(q - 1)] + m(t[q], t[q - 1]);
    }
  };
  for (int round = 0; round < opt_.max_improve_rounds; ++round) {
    bool improved = false;
    // --- 2-opt: reverse t[i..j] ---
    prefix();
    for (int i = 1; i < last_movable; ++i) {
      for (int j = i + 1; j <= last_movable; ++j) {
        const double cur = fwd[size_t(n - 1)];
        double delta = m(t[i - 1], t[j]) - m(t[i - 1], t[i]);
        delta += (bwd[size_t(j)] - bwd[size_t(i)]) - (fwd[size_t(j)] - fwd[size_t(i)]);
        if (j + 1 < n) delta += m(t[i], t[j + 1]) - m(t[j], t[j + 1]);
        if (gains(delta, cur)) {
          std::reverse(t.begin() + i, t.begin() + j + 1);
          prefix();
          improved = true;
        }
      }
    }
    // --- Or-opt: move t[i..i+L-1] between t[p-1] and t[p] (or to the end), maybe reversed ---
    for (int len = 1; len <= 3; ++len) {
      for (int i = 1; i + len - 1 <= last_movable; ++i) {
        const int a = t[i - 1], s0 = t[i], s1 = t[i + len - 1];
        const bool has_next = i + len < n;
        const int b = has_next ? t[i + len] : -1;
        const double remove_gain = m(a, s0) + (has_next ? m(s1, b) - m(a, b) : 0.0);
        double internal_fwd = 0, internal_rev = 0;
        for (int q = i; q < i + len - 1; ++q) {
          internal_fwd += m(t[q], t[q + 1]);
          internal_rev += m(t[q + 1], t[q]);
        }
        double best = 0;
        int best_p = -1;
        bool best_rev = false;
        // Candidate insertion points p in the tour without the segment: between t[p-1], t[p].
        for (int p = 1; p <= n; ++p) {
          if (p >= i && p <= i + len) continue;  // same place or inside the segment
          const int u = t[p - 1];
          const bool at_end = p == n;
          if (at_end && fixed_end) continue;
          if (p - 1 >= i && p - 1 < i + len) continue;
          const int w = at_end ? -1 : t[p];
          for (int rev = 0; rev < 2; ++rev) {
            if (rev && len == 1) break;
            const int first = rev ? s1 : s0, lastn = rev ? s0 : s1;
            double add = m(u, first) + (at_end ? 0.0 : m(lastn, w) - m(u, w));
            add += (rev ? internal_rev : internal_fwd) - internal_fwd;
            const double delta = add - remove_gain;
            if (delta < best && gains(delta, fwd[size_t(n - 1)])) {
              best = delta;
              best_p = p;
              best_rev = rev;
            }
          }
        }
        if (best_p < 0) continue;
        buf.assign(t.begin() + i, t.begin() + i + len);
        if (best_rev) std::reverse(buf.begin(), buf.end());
        std::vector<int> nt;
        nt.reserve(size_t(n));
        for (int q = 0; q <= n; ++q) {
          if (q == best_p) nt.insert(nt.end(), buf.begin(), buf.end());
          if (q < n && (q < i || q >= i + len)) nt.push_back(t[q]);
        }
        t.swap(nt);
        prefix();
        improved = true;
      }
    }
    if (!improved) break;
  }
}

}  // namespace storey::core::plan
