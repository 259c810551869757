// Runs the matrix: one `storey sim` child process per RunSpec (posix_spawn), at most `jobs` at a
// time, each writing into DIR/runs/.../seed<N>.partial/ which becomes seed<N>/ when the child
// exits, so a folder without ".partial" always holds a whole record (resumability: a run whose
// folder holds a complete metrics.json is not redone). The child's stdout and stderr go to the
// folder's log.txt; the runner adds eval.json (exit status, reason, wall time, command).
// Single-threaded: the calling thread polls its children; no threads are created.
#pragma once

#include <cstdio>
#include <string>
#include <vector>

#include "tools/eval/run_record.hpp"

namespace storey::tools::eval {

struct RunnerOptions {
  std::string storey;       // the `storey` executable
  int jobs = 1;             // children at once
  std::string out_dir;      // runs go to out_dir/runs/...
  TimeLimits time_limits;   // each run's --time-limit, by scene
  std::string config;       // --config of every run ("" = none)
  FILE* progress = stderr;  // progress bar and failure lines; nullptr = quiet
};

class Runner {
 public:
  explicit Runner(RunnerOptions o) : o_(std::move(o)) {}
  // Runs every spec not finished before; one outcome per spec, in spec order. Never throws for
  // a failed run (recorded as failed with its reason); throws std::runtime_error when out_dir
  // cannot be written.
  std::vector<RunOutcome> run(const std::vector<RunSpec>& specs);
  // Async-signal-safe: no new child is started; running ones get SIGTERM and are waited for,
  // their .partial folders removed and their specs reported not_run.
  static void request_stop();
  static bool stop_requested();
  static void clear_stop();  // before reusing runners after a stop (tests)

 private:
  RunnerOptions o_;
};

// "1h02m", "4m05s", "12s".
std::string format_duration(double seconds);

}  // namespace storey::tools::eval
