// storey-eval's command line (DESIGN §7): the matrix (flags or a preset), seeds, parallelism,
// the simulated time limits, the output folder and where the `storey` executable is.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "tools/eval/run_matrix.hpp"

namespace storey::tools::eval {

struct EvalOptions {
  std::vector<MatrixGroup> groups;  // from --scenes/--methods/--ablations or --preset
  std::vector<std::string> presets;
  std::vector<uint64_t> seeds;       // --seeds N -> 1..N; --seeds 3,7 -> {3, 7}
  int jobs = 0;                      // 0 = the machine's cores
  TimeLimits time_limits;            // --time-limit: simulated seconds per run, per scene
  std::string out_dir = "out/eval";  // runs/, results.md, results.csv, results.json, PNGs
  std::string storey;                // "" = the `storey` next to storey-eval
  std::string config;                // passed on as --config when set
  bool report_only = false;          // aggregate the runs already in out_dir, run nothing
  bool help = false;
};

struct ParseResult {
  EvalOptions options;
  std::string error;  // "" = ok; otherwise names the flag: "--seeds x: expected ..."
  bool ok() const { return error.empty(); }
};

// args excludes the program name.
ParseResult parse_eval_args(const std::vector<std::string>& args);
void print_eval_usage(FILE* out);

// Default matrix pieces (all built-in paper scenes plus house; every method).
const std::vector<std::string>& default_scenes();
const std::vector<std::string>& default_methods();

}  // namespace storey::tools::eval
