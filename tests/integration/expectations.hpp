#pragma once
// Issue #9's bar for a whole exploration, shared by the integration tests: ended complete, every
// one of the scene's floors explored (>= 90 % of its traversable ground truth), no collision or
// fall.
#include <cstdint>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "tools/sim/sim_run.hpp"

namespace storey::tools::sim {

// A lockstep run of `scene` with the default configuration, no progress lines (coverage is still
// sampled at the end).
inline SimRunOptions quiet_run(const std::string& scene, uint32_t seed, double time_limit_s) {
  SimRunOptions o;
  o.scene = scene;
  o.seed = seed;
  o.time_limit_s = time_limit_s;
  o.progress_period_s = 0;
  o.progress = [](const std::string&) {};
  return o;
}

// config/default.yaml with the given "key: value" texts replaced, written to `name` in the test's
// temporary directory; empty if one is not in the file.
inline std::string edited_default_config(
    const std::string& name, const std::vector<std::pair<std::string, std::string>>& edits) {
  std::ifstream in(std::string(STOREY_SOURCE_DIR) + "/config/default.yaml");
  std::stringstream ss;
  ss << in.rdbuf();
  std::string text = ss.str();
  for (const auto& [from, to] : edits) {
    const size_t at = text.find(from);
    if (at == std::string::npos) return "";
    text.replace(at, from.size(), to);
  }
  const std::string path = testing::TempDir() + "/" + name;
  std::ofstream(path) << text;
  return path;
}

inline void expect_every_floor_explored_safely(const SimRunResult& r, int floors) {
  const RunMetrics& m = r.metrics;
  EXPECT_TRUE(r.completed) << r.end_reason;
  EXPECT_EQ(m.collisions, 0u);
  EXPECT_EQ(m.falls, 0u);
  EXPECT_EQ(m.floors_total, floors);
  EXPECT_EQ(m.floors_explored, floors);
  for (const auto& f : m.per_floor) EXPECT_GE(f.traversable_coverage, 0.9) << "floor at " << f.z_m;
}

}  // namespace storey::tools::sim
