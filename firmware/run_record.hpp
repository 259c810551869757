#pragma once
// The run record of `storey run` (DESIGN §7): metrics.json (the keys that mean something without
// ground truth), latency.md, trace.json, map.ply, graph.json and report.md. Written on the main
// thread after the tasks stopped (it reads the map owner's state).
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "drivers/go2/robot_link.hpp"
#include "drivers/lidar/udp_receiver.hpp"
#include "firmware/autonomy.hpp"
#include "firmware/live_platform.hpp"

namespace storey::firmware {

struct LiveRunSummary {
  std::string command;     // the command line, for report.md
  std::string config;      // configuration file
  std::string end_reason;  // "exploration complete", "duration reached", "stopped by SIGINT" ...
  bool completed = false;  // the planner reported exploration complete
  double run_time_s = 0;   // wall time from start to the commanded stop [s]
  double trajectory_length_m = 0;
  uint64_t safety_stops = 0;        // before the shutdown's own (operator) stop
  std::vector<int> floors_visited;  // floor hints the robot stood on
  std::string record_path;          // --record capture ("" = none)
  uint64_t record_written = 0;      // datagrams written to it
  std::vector<std::string> log;     // the firmware's log lines (safety stops ...)
  std::vector<std::string> warnings;
};

// Plain per-task latency rows (exec p50/p99/max, jitter p99, overruns) from the scheduler.
std::string latency_table_markdown(const std::vector<rt::TaskReport>& reports);

// Writes the record into `dir` (created). Returns the files written; `error` names the first
// file that could not be written (the others are still attempted).
std::vector<std::string> write_live_record(const std::string& dir, Autonomy& autonomy,
                                           LivePlatform& platform, const LiveRunSummary& summary,
                                           std::string* error);

}  // namespace storey::firmware
