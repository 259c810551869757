// Aggregation of the runs into the paper's tables (Section V, Tables I-IV): mean and sample
// standard deviation over seeds, failures counted ("n/a (k of N failed)"), plus the per-run CSV,
// the JSON and the coverage plots.
#pragma once

#include <string>
#include <vector>

#include "tools/eval/run_record.hpp"

namespace storey::tools::eval {

struct Stat {
  size_t n = 0;
  double mean = 0.0, std = 0.0;  // sample standard deviation (n - 1); 0 for one value
};
Stat stat_of(const std::vector<double>& v);

// The runs of one scene x method x ablation, seeds in matrix order.
struct RunGroup {
  std::string scene, method, ablation;
  std::vector<const RunOutcome*> runs;
  size_t finished() const;
  size_t failed() const;
  size_t not_run() const;
  std::string variant() const { return ablation.empty() ? method : method + "-" + ablation; }
};
std::vector<RunGroup> group_runs(const std::vector<RunOutcome>& outcomes);

// Per-floor times as reported in Table II: the robot's time on floor f until the floor reached 90 %
// (FloorRecord::time_on_floor_s; transitions excluded, as in the paper). A record without
// tracking.csv: floor f's time to 90 %, for f >= 1 from the previous floor's 90 % (transitions
// included). Negative when not reached.
double floor_time(const MetricsRecord& m, size_t f);

// "530 ± 17" (decimals after the point), or `empty` when there is no value.
std::string format_stat(const Stat& s, int decimals, const std::string& empty);

struct ResultsInput {
  std::vector<RunOutcome> outcomes;
  std::string command;  // the storey-eval command line, quoted in results.md
  std::vector<std::pair<std::string, std::string>> plots;  // (scene, file name in DIR)
};
std::string results_markdown(const ResultsInput& in);
std::string results_csv(const std::vector<RunOutcome>& outcomes);
std::string results_json(const ResultsInput& in);

// Writes DIR/coverage_<scene>.png, results.md, results.csv and results.json; returns the paths.
// Throws std::runtime_error naming the file that could not be written.
std::vector<std::string> write_results(const std::string& dir, const std::vector<RunOutcome>& o,
                                       const std::string& command);

}  // namespace storey::tools::eval
