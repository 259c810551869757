// What one run left behind: its metrics.json (fields of tools/sim/metrics.cpp), the end reason
// (from metrics.json when it carries one, else the Outcome line of report.md) and the runner's
// own eval.json (exit status, failure reason, wall time).
#pragma once

#include <cmath>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "tools/eval/run_matrix.hpp"

namespace storey::tools::eval {

struct FloorRecord {
  double z_m = 0.0;
  double time_s = -1.0;  // first time the floor reached 90 % coverage; < 0 = never
  double traversable_coverage = 0.0;
  // Of [0, time_s], the time the robot stood on this floor (paper Table II: "complete exploration
  // within each floor, excluding cross-floor transitions"); from tracking.csv; NaN when the
  // record has no tracking.csv or the floor never reached 90 %.
  double time_on_floor_s = std::nan("");
};

struct MetricsRecord {
  bool success = false;
  int floors_total = 0, floors_explored = 0;
  double exploration_time_s = 0.0, trajectory_length_m = 0.0;
  double traversable_volume_m3 = 0.0, occupied_volume_m3 = 0.0;
  double gt_traversable_volume_m3 = 0.0, gt_occupied_volume_m3 = 0.0;
  double traversable_coverage = 0.0;
  std::vector<FloorRecord> per_floor;
  double collisions = 0, falls = 0, safety_stops = 0;
  // Time moving faster than 0.2 m/s (tools/sim kWalkingSpeed); NaN: not in the record (a
  // metrics.json from before session 12; null in results.json, skipped by the statistics).
  double walking_time_s = std::nan("");
  std::vector<std::pair<double, double>> coverage_over_time;  // (t [s], coverage 0..1)
  std::string end_reason;                                     // "" when not recorded
  std::string commit;  // the storey build's commit; "" in records from before session 34
};

// A metrics.json is complete when it parses as a whole and holds every field above (a record cut
// off while being written does not parse). nullopt with *error naming the file otherwise.
std::optional<MetricsRecord> read_metrics_json(const std::string& path, std::string* error);
// Fills each floor's time_on_floor_s from a tracking.csv (t_s, x_m, y_m, z_m, ... at a fixed
// rate; the robot is on a floor when its foot lies within kOnFloorM of the floor's z). False (and
// nothing changed) when the file is missing or has no sample.
constexpr double kOnFloorM = 0.3;
bool add_time_on_floor(const std::string& tracking_csv_path, MetricsRecord& m);
// The reason after "Outcome: **...** - " in report.md; "" when there is none.
std::string read_report_outcome(const std::string& report_md_path);
// The last non-empty line of a text file (a failed child's reason); "" when none.
std::string last_line(const std::string& path);
// The simulated time of the last `storey sim` progress line ("[sim   12.5 s] ...") in the last
// 4 KiB of a log; -1 when there is none.
double last_simulated_time(const std::string& log_path);

enum class RunStatus {
  finished,  // complete metrics.json (success or not: a baseline that stays on one floor finishes)
  failed,    // the child left no complete metrics.json, or the run itself failed ("run failed:")
  not_run,   // nothing in the folder (--report-only, or interrupted)
};
const char* to_string(RunStatus s);

struct RunOutcome {
  RunSpec spec;
  RunStatus status = RunStatus::not_run;
  bool resumed = false;  // finished in an earlier storey-eval invocation
  int exit_code = -1;    // the child's exit code; -1 when unknown (killed, or not recorded)
  std::string reason;    // failed: why (the child's last stderr line); finished: end reason
  double wall_s = 0.0;   // wall-clock seconds the child took (0 when unknown)
  double time_limit_s = std::nan("");  // the run's --time-limit, from eval.json's command
  MetricsRecord metrics;               // valid when status == finished
};

// Reads a run folder (DIR/runs/...): finished when metrics.json is complete; failed when the
// runner's eval.json says so; not_run otherwise. Table II's floor times come from tracking.csv,
// else from eval.json (a record kept without its tracking.csv, such as docs/eval/).
RunOutcome load_outcome(const RunSpec& spec, const std::string& run_dir);
// Writes run_dir/eval.json for `o` (status, exit code, reason, wall time, the command, and Table
// II's time on each floor when the folder has metrics.json and tracking.csv).
void write_eval_record(const RunOutcome& o, const std::string& run_dir,
                       const std::vector<std::string>& command);

}  // namespace storey::tools::eval
