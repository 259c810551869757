// `storey-sim --scene house --config` and `storey run --config` as two processes over loopback
// UDP (DESIGN §1: the firmware cannot tell the simulator from the robot). Ports are made unique
// per test process by a temporary config that includes config/hil.yaml.
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fcntl.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

extern char** environ;

namespace {

namespace fs = std::filesystem;

std::string read_file(const std::string& p) {
  std::ifstream f(p);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

pid_t spawn(const std::vector<std::string>& args, const std::string& out, const std::string& err) {
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 1, out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_addopen(&fa, 2, err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  std::vector<char*> argv;
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  pid_t pid = -1;
  const int rc = posix_spawn(&pid, argv[0], &fa, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&fa);
  return rc == 0 ? pid : -1;
}

// Exit status, or -1 after `timeout_s` (the child is then killed).
int wait_for(pid_t pid, double timeout_s) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  int st = 0;
  while (std::chrono::steady_clock::now() < end) {
    const pid_t r = waitpid(pid, &st, WNOHANG);
    if (r == pid) return WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  kill(pid, SIGKILL);
  waitpid(pid, &st, 0);
  return -1;
}

double number(const std::string& json, const std::string& key) {
  const std::regex re("\"" + key + "\": *(-?[0-9.eE+-]+)");
  std::smatch m;
  if (!std::regex_search(json, m, re)) return std::nan("");
  return std::stod(m[1]);
}

struct TaskLatency {
  std::string name;
  double p99_ms, budget_ms;
};
std::vector<TaskLatency> latencies(const std::string& json) {
  std::vector<TaskLatency> v;
  const std::regex re(
      "\"([a-z]+)\": \\{\"p50_ms\": [0-9.]+, \"p99_ms\": ([0-9.]+), \"max_ms\": [0-9.]+, "
      "\"overruns\": [0-9]+, \"budget_ms\": ([0-9.]+)");
  for (auto it = std::sregex_iterator(json.begin(), json.end(), re); it != std::sregex_iterator();
       ++it)
    v.push_back({(*it)[1], std::stod((*it)[2]), std::stod((*it)[3])});
  return v;
}

TEST(Hil, StoreyRunExploresTheHouseAgainstStoreySim) {
  const std::string bin = STOREY_BINARY_DIR;
  const std::string dir = fs::temp_directory_path() / ("storey_hil_" + std::to_string(getpid()));
  fs::create_directories(dir);
  const int base = 20000 + (getpid() % 2000) * 10;
  {
    std::ofstream c(dir + "/hil.yaml");
    c << "include: " << STOREY_SOURCE_DIR << "/config/hil.yaml\n"
      << "sensor:\n  data_port: " << base << "\n"
      << "link:\n  udp:\n    robot_port: " << base + 1 << "\n    local_port: " << base + 2 << "\n";
  }
  const pid_t sim = spawn(
      {bin + "/storey-sim", "--scene", "house", "--config", dir + "/hil.yaml", "--duration", "40"},
      dir + "/sim.json", dir + "/sim.err");
  ASSERT_GT(sim, 0);
  const pid_t run = spawn({bin + "/storey", "run", "--config", dir + "/hil.yaml", "--duration",
                           "20", "--out", dir + "/out"},
                          dir + "/run.out", dir + "/run.err");
  ASSERT_GT(run, 0);
  const int run_rc = wait_for(run, 45);
  kill(sim, SIGTERM);  // ends cleanly and prints its summary line
  const int sim_rc = wait_for(sim, 10);
  EXPECT_EQ(run_rc, 0) << read_file(dir + "/run.err");
  EXPECT_EQ(sim_rc, 0) << read_file(dir + "/sim.err");

  const std::string m = read_file(dir + "/out/metrics.json");
  const std::string s = read_file(dir + "/sim.json");
  ASSERT_FALSE(m.empty()) << read_file(dir + "/run.err");
  ASSERT_FALSE(s.empty()) << read_file(dir + "/sim.err");
  // LiDAR: every datagram accepted, scans at ~10 Hz, none without a pose past start-up.
  EXPECT_EQ(number(m, "dropped"), 0);
  EXPECT_GE(number(m, "scans"), 150);
  EXPECT_GT(number(m, "datagrams"), 10000);
  // The robot moved, safely; the graph grew.
  EXPECT_GT(number(s, "distance_m"), 0.5);
  EXPECT_GT(number(m, "trajectory_length_m"), 0.5);
  EXPECT_EQ(number(s, "collisions"), 0);
  EXPECT_EQ(number(s, "falls"), 0);
  EXPECT_GT(number(m, "nodes"), 20);
  EXPECT_GT(number(m, "commands_sent"), 500);
  EXPECT_EQ(number(m, "commands_refused"), 0);
  // Latency: every task's p99 and budget reported. Wall-clock figures are not asserted: they
  // depend on the machine's load (session 42: the plan task's p99 was 1758 ms against its
  // 200 ms budget while three simulations shared the 2 cores). The budgets are measured side
  // by side by the profiling commands (docs/PERFORMANCE.md "run mode").
  const auto lat = latencies(m);
  ASSERT_EQ(lat.size(), 6u) << m;
  for (const auto& l : lat) {
    std::printf("  %-9s p99 %8.3f ms  budget %8.3f ms\n", l.name.c_str(), l.p99_ms, l.budget_ms);
    EXPECT_TRUE(std::isfinite(l.p99_ms) && l.p99_ms >= 0) << l.name;
    EXPECT_GT(l.budget_ms, 0) << l.name;
  }
  for (const char* f : {"latency.md", "trace.json", "map.ply", "graph.json", "report.md"})
    EXPECT_TRUE(fs::exists(dir + "/out/" + f)) << f;
  if (!HasFailure()) fs::remove_all(dir);
}

}  // namespace
