#pragma once
// Open-tour TSP over a cost matrix (paper Sec. IV-C global zone order, Sec. IV-D Stage 1 cluster
// order). The tour starts at a fixed node (the robot) and visits every node once; it may end at
// a fixed node (the terminal anchor c_anc) or anywhere. Costs may be asymmetric.
//
// Exact Held-Karp DP up to TspOptions::exact_max_n nodes; beyond, cheapest insertion followed by
// 2-opt and Or-opt local search with the endpoints held fixed. Deterministic: no randomness, ties
// broken by index.
#include <cstdint>
#include <span>
#include <vector>

namespace storey::core::plan {

struct TspOptions {
  int exact_max_n = 12;         // Held-Karp up to this many nodes (memory 2^n * n doubles)
  int max_improve_rounds = 50;  // 2-opt / Or-opt rounds (each a full sweep) in the heuristic
};

enum class TspStatus : uint8_t {
  kOk = 0,
  kBadInput,    // size mismatch, start/end out of range, end == start with n > 1, NaN/negative cost
  kInfeasible,  // every complete tour has an infinite cost
};
const char* to_string(TspStatus s);

struct TspResult {
  TspStatus status = TspStatus::kBadInput;
  std::vector<int> order;  // node indices, order.front() == start, order.back() == end if fixed
  double cost = 0;         // sum of cost(order[i], order[i+1])
  bool exact = false;      // true if solved by Held-Karp (optimal)
};

// Row-major n x n cost matrix view: cost(i, j) = travel cost from i to j (+inf: no edge).
struct CostMatrix {
  int n = 0;
  std::span<const double> c;
  double operator()(int i, int j) const { return c[size_t(i) * size_t(n) + size_t(j)]; }
};

// Reusable solver: keeps its scratch between calls (no allocation once grown).
class TspSolver {
 public:
  explicit TspSolver(const TspOptions& options = {}) : opt_(options) {}

  // end < 0: open tour ending anywhere. Diagonal entries are ignored.
  TspResult solve(const CostMatrix& m, int start, int end = -1);
  // Always the heuristic / always the DP (tests and benchmarks).
  TspResult solve_heuristic(const CostMatrix& m, int start, int end = -1);
  TspResult solve_exact(const CostMatrix& m, int start, int end = -1);

  const TspOptions& options() const { return opt_; }

 private:
  TspStatus validate(const CostMatrix& m, int start, int end) const;
  void improve(const CostMatrix& m, std::vector<int>& tour, bool fixed_end);

  TspOptions opt_;
  std::vector<double> dp_;
  std::vector<int8_t> parent_;
  std::vector<int> nodes_;
};

// Cost of visiting `order` in sequence (+inf if any leg is +inf).
double path_cost(const CostMatrix& m, std::span<const int> order);

}  // namespace storey::core::plan
