// Helpers shared by the tools_eval tests: a fresh temp folder and fixture metrics.json files
// written by the simulator's own writer (tools/sim/metrics.cpp), so the reader is tested against
// the real format.
#pragma once

#include <stdlib.h>

#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

#include "tools/sim/metrics.hpp"

namespace storey::tools::eval::test {

inline std::string fresh_dir(const std::string& tag) {
  std::string t =
      std::filesystem::temp_directory_path().string() + "/storey_eval_" + tag + "_XXXXXX";
  if (!mkdtemp(t.data())) throw std::runtime_error("mkdtemp failed");
  return t;
}

inline void write_text(const std::string& path, const std::string& text) {
  std::filesystem::create_directories(std::filesystem::path(path).parent_path());
  std::ofstream(path) << text;
}

// A two-floor run: time t, distance d, floor times f1/f2 (< 0: never), coverage steps.
inline sim::RunMetrics fixture_metrics(double t, double d, double f1, double f2, double occ = 600) {
  sim::RunMetrics m;
  m.success = f1 >= 0 && f2 >= 0;
  m.floors_total = 2;
  m.floors_explored = (f1 >= 0) + (f2 >= 0);
  m.exploration_time_s = t;
  m.trajectory_length_m = d;
  m.traversable_volume_m3 = 250;
  m.occupied_volume_m3 = occ;
  m.gt_traversable_volume_m3 = 270;
  m.gt_occupied_volume_m3 = 650;
  m.traversable_coverage = 0.5 * ((f1 >= 0 ? 0.95 : 0.4) + (f2 >= 0 ? 0.93 : 0.0));
  m.per_floor = {{0.0, f1, f1 >= 0 ? 0.95 : 0.4}, {3.0, f2, f2 >= 0 ? 0.93 : 0.0}};
  m.coverage_over_time = {{0, 0.0}, {t / 2, 0.3}, {t, m.traversable_coverage}};
  return m;
}

inline void write_run(const std::string& dir, const sim::RunMetrics& m, const std::string& why) {
  std::filesystem::create_directories(dir);
  sim::write_metrics_json(m, dir + "/metrics.json");
  write_text(dir + "/report.md", "# storey sim: x\n\nOutcome: **" +
                                     std::string(m.success ? "success" : "no success") + "** - " +
                                     why + "\n\n| metric | value |\n");
}

}  // namespace storey::tools::eval::test
