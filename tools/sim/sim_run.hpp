// One lockstep exploration (DESIGN §7 `storey sim`): scene + ground truth + WorldSim behind a
// SimPlatform, the firmware's Autonomy task table on a VirtualClock, the world stepped between
// 10 ms scheduler slices (deterministic: same inputs and seed, same metrics, bit for bit), and
// the run record (metrics.json, map.ply, graph.json, trace.json, latency.md, PNGs, report.md).
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "tools/sim/metrics.hpp"
#include "tools/sim/scene.hpp"

namespace storey::tools::sim {

struct SimRunOptions {
  std::string scene = "office";    // built-in name or file
  std::optional<StartPose> start;  // yaw in radians
  std::string sensor = "vlp16";    // vlp16 | mid360
  uint64_t seed = 1;
  std::string method = "storey";
  std::string ablation;          // "" = full method
  double time_limit_s = 1200;    // simulated seconds
  std::string out_dir;           // "" = no record
  std::string config;            // "" = config/default.yaml (or built-in defaults)
  double progress_period_s = 5;  // simulated seconds between progress lines (0 = none)
  std::function<void(const std::string&)> progress;  // default: stderr
};

struct SimRunResult {
  RunMetrics metrics;
  bool completed = false;  // the planner reported exploration complete
  std::string end_reason;
  std::string report_path;       // out_dir/report.md when written
  std::vector<std::string> log;  // the firmware's log lines (safety stops ...)
};

// Names of the method and ablation switches; unknown ones (and an ablation with a baseline
// method) are refused by run_exploration with std::invalid_argument (one line naming the flag).
const std::vector<std::string>& known_methods();
const std::vector<std::string>& known_ablations();

// Throws std::invalid_argument for bad options (scene, sensor, config...), std::runtime_error
// when the record cannot be written. A failure during the run still writes the record.
SimRunResult run_exploration(const SimRunOptions& options);

}  // namespace storey::tools::sim
