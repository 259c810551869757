// storey-eval -> storey sim -> metrics.json -> results.md/CSV, for real, on the small
// test_box_room scene; then a second invocation that must redo nothing finished.
#include <gtest/gtest.h>
#include <stdlib.h>
#include <sys/wait.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;

std::string slurp(const std::string& path) {
  std::ifstream f(path);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> v;
  std::istringstream ss(text);
  for (std::string l; std::getline(ss, l);) v.push_back(l);
  return v;
}

int run_eval(const std::string& out) {
  const std::string cmd = std::string(STOREY_BINARY_DIR) +
                          "/storey-eval --scenes test_box_room --methods storey,no-such-method "
                          "--seeds 2 --time-limit 20 --jobs 2 --out " +
                          out + " > " + out + ".stdout 2> " + out + ".stderr";
  const int st = std::system(cmd.c_str());
  return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

TEST(EvalEndToEnd, RealRunsTablesAndResumption) {
  std::string tmpl = fs::temp_directory_path().string() + "/storey_eval_e2e_XXXXXX";
  ASSERT_TRUE(mkdtemp(tmpl.data()));
  const std::string out = tmpl + "/eval";

  ASSERT_EQ(run_eval(out), 0) << slurp(out + ".stderr");
  EXPECT_EQ(slurp(out + ".stdout"), out + "/results.md\n");
  const std::string md = slurp(out + "/results.md");
  EXPECT_NE(md.find("| test_box_room | storey | 2/2 |"), std::string::npos) << md;
  EXPECT_NE(
      md.find("| test_box_room | no-such-method | 0/2 (2 failed) | n/a | n/a | n/a | n/a (2 of 2 "
              "failed) |"),
      std::string::npos)
      << md;
  EXPECT_NE(md.find("| test_box_room | no-such-method | 2 of 2 | storey sim: --method "
                    "no-such-method"),
            std::string::npos)
      << md;
  EXPECT_TRUE(fs::exists(out + "/coverage_test_box_room.png"));
  EXPECT_TRUE(fs::exists(out + "/results.json"));

  auto csv = lines_of(slurp(out + "/results.csv"));
  ASSERT_EQ(csv.size(), 5u) << slurp(out + "/results.csv");
  for (int seed = 1; seed <= 2; ++seed) {
    const std::string& row = csv[size_t(seed)];
    // scene,method,ablation,seed,status,resumed,exit_code,...
    EXPECT_EQ(row.rfind("test_box_room,storey,full," + std::to_string(seed) + ",finished,0,", 0),
              0u)
        << row;
    const std::string dir = out + "/runs/test_box_room/storey/seed" + std::to_string(seed);
    EXPECT_TRUE(fs::exists(dir + "/metrics.json")) << slurp(dir + "/log.txt");
    EXPECT_TRUE(fs::exists(dir + "/report.md")) << slurp(dir + "/log.txt");
    EXPECT_NE(slurp(dir + "/log.txt").find("storey sim: scene test_box_room"), std::string::npos);
  }
  EXPECT_EQ(csv[3].rfind("test_box_room,no-such-method,full,1,failed,0,2,", 0), 0u) << csv[3];

  // The numbers are the simulator's: a real exploration mapped most of the room.
  const std::string m1 = slurp(out + "/runs/test_box_room/storey/seed1/metrics.json");
  EXPECT_NE(m1.find("\"traversable_coverage\": 0."), std::string::npos) << m1;

  // Again: the finished runs are kept as they are (same log file), the failed ones retried.
  const auto log_time = fs::last_write_time(out + "/runs/test_box_room/storey/seed1/log.txt");
  ASSERT_EQ(run_eval(out), 0) << slurp(out + ".stderr");
  EXPECT_EQ(fs::last_write_time(out + "/runs/test_box_room/storey/seed1/log.txt"), log_time);
  csv = lines_of(slurp(out + "/results.csv"));
  ASSERT_EQ(csv.size(), 5u);
  EXPECT_EQ(csv[1].rfind("test_box_room,storey,full,1,finished,1,", 0), 0u) << csv[1];
  EXPECT_EQ(csv[2].rfind("test_box_room,storey,full,2,finished,1,", 0), 0u) << csv[2];
  EXPECT_EQ(csv[3].rfind("test_box_room,no-such-method,full,1,failed,0,", 0), 0u) << csv[3];
  EXPECT_NE(slurp(out + ".stderr").find("2 of 4 runs already finished (resumed), 2 to run"),
            std::string::npos)
      << slurp(out + ".stderr");
  fs::remove_all(tmpl);
}

}  // namespace
