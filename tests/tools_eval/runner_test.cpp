// The runner against a stand-in `storey` (a shell script that logs each call and writes a
// metrics.json, or refuses a method like `storey sim` does): resumability, failure records,
// interrupted folders.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "test_util.hpp"
#include "tools/eval/runner.hpp"

namespace storey::tools::eval {
namespace {

namespace fs = std::filesystem;

struct FakeStorey {
  std::string dir, script, calls;

  FakeStorey() {
    dir = test::fresh_dir("runner");
    script = dir + "/storey";
    calls = dir + "/calls.txt";
    std::ofstream f(script);
    f << "#!/bin/sh\n"
         "out=''; seed=''; method=''; ablation=full; limit=''\n"
         "while [ $# -gt 0 ]; do case \"$1\" in --out) out=$2; shift;; --seed) seed=$2; shift;;\n"
         "  --time-limit) limit=$2; shift;;\n"
         "  --method) method=$2; shift;; --ablation) ablation=$2; shift;; esac; shift; done\n"
         "echo \"$method $ablation $seed\" >> '"
      << calls
      << "'\n"
         "echo 'storey sim: scene x, seed' $seed, time limit $limit >&2\n"
         "if [ \"$method\" = refused ]; then\n"
         "  echo 'storey sim: --method refused: not available yet' >&2; exit 2; fi\n"
         "if [ \"$method\" = crash ]; then kill -SEGV $$; fi\n"
         "t=$((100 + 10 * seed))\n"
         "cat > \"$out/metrics.json\" <<EOF\n"
         "{\"success\": true, \"floors_total\": 1, \"floors_explored\": 1,\n"
         " \"exploration_time_s\": $t, \"trajectory_length_m\": 50, \"traversable_volume_m3\": 1,\n"
         " \"occupied_volume_m3\": 2, \"gt_traversable_volume_m3\": 1, \"gt_occupied_volume_m3\": "
         "2,\n"
         " \"traversable_coverage\": 0.97, \"per_floor\": [{\"z_m\": 0, \"time_s\": 90, "
         "\"traversable_coverage\": 0.97}],\n"
         " \"collisions\": 0, \"falls\": 0, \"safety_stops\": 0, \"latency\": {},\n"
         " \"coverage_over_time\": [[0, 0], [$t, 0.97]]}\n"
         "EOF\n"
         "echo 'Outcome: **success** - exploration complete' > \"$out/report.md\"\n"
         "echo \"$out/report.md\"\n";
    f.close();
    chmod(script.c_str(), 0755);
  }
  ~FakeStorey() { fs::remove_all(dir); }

  std::vector<std::string> call_lines() const {
    std::ifstream f(calls);
    std::vector<std::string> v;
    for (std::string l; std::getline(f, l);) v.push_back(l);
    return v;
  }
  Runner runner(const std::string& out, int jobs = 2) const {
    return Runner({script, jobs, out, TimeLimits{30, {}}, "", nullptr});
  }
};

TEST(Runner, RunsEverySpecAndRecordsFailuresWithTheirReason) {
  FakeStorey fake;
  const std::string out = fake.dir + "/eval";
  const auto specs = expand_matrix({{{"box"}, {"storey", "refused"}, {"full"}}}, {1, 2});
  const auto res = fake.runner(out).run(specs);
  ASSERT_EQ(res.size(), 4u);
  EXPECT_EQ(fake.call_lines().size(), 4u);
  for (size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(res[i].status, RunStatus::finished) << res[i].reason;
    EXPECT_FALSE(res[i].resumed);
    EXPECT_EQ(res[i].exit_code, 0);
    EXPECT_EQ(res[i].reason, "exploration complete");
    EXPECT_DOUBLE_EQ(res[i].metrics.exploration_time_s, 100.0 + 10.0 * double(i + 1));
    // The child's output is in the folder's log; the folder is final (no .partial left).
    const std::string dir = out + "/" + specs[i].rel_dir();
    std::ifstream log(dir + "/log.txt");
    std::stringstream ss;
    ss << log.rdbuf();
    EXPECT_NE(
        ss.str().find("storey sim: scene x, seed " + std::to_string(i + 1) + ", time limit 30"),
        std::string::npos);
    EXPECT_TRUE(fs::exists(dir + "/eval.json"));
    EXPECT_FALSE(fs::exists(dir + ".partial"));
  }
  for (size_t i = 2; i < 4; ++i) {
    EXPECT_EQ(res[i].status, RunStatus::failed);
    EXPECT_EQ(res[i].exit_code, 2);
    EXPECT_EQ(res[i].reason, "storey sim: --method refused: not available yet");
    // The failure survives in the folder for --report-only.
    const RunOutcome again = load_outcome(specs[i], out + "/" + specs[i].rel_dir());
    EXPECT_EQ(again.status, RunStatus::failed);
    EXPECT_EQ(again.reason, res[i].reason);
  }
}

std::string log_of(const std::string& dir) {
  std::ifstream f(dir + "/log.txt");
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

TEST(Runner, EachSceneRunsWithItsOwnTimeLimit) {
  FakeStorey fake;
  const std::string out = fake.dir + "/eval";
  const auto specs = expand_matrix({{{"box", "scenes/hall.yaml"}, {"storey"}, {"full"}}}, {1});
  const auto res =
      Runner({fake.script, 1, out, TimeLimits{30, {{"hall", 45.5}}}, "", nullptr}).run(specs);
  ASSERT_EQ(res.size(), 2u);
  EXPECT_NE(log_of(out + "/" + specs[0].rel_dir()).find("time limit 30\n"), std::string::npos);
  // Keyed by the folder name (the file's stem), as the tables name the scene.
  EXPECT_NE(log_of(out + "/" + specs[1].rel_dir()).find("time limit 45.5\n"), std::string::npos);
  // And the records say so (eval.json's command), for the tables' footnote.
  EXPECT_DOUBLE_EQ(res[0].time_limit_s, 30);
  EXPECT_DOUBLE_EQ(load_outcome(specs[1], out + "/" + specs[1].rel_dir()).time_limit_s, 45.5);
}

TEST(Runner, ResumesFinishedRunsAndRetriesFailedAndBrokenOnes) {
  FakeStorey fake;
  const std::string out = fake.dir + "/eval";
  const auto specs = expand_matrix({{{"box"}, {"storey", "refused"}, {"full"}}}, {1, 2, 3});
  fake.runner(out).run(specs);
  ASSERT_EQ(fake.call_lines().size(), 6u);

  // Seed 2's metrics.json cut off mid-write (an old, interrupted layout), seed 3 a stale
  // .partial folder: the first is redone, the second cleaned and ignored.
  const std::string seed2 = out + "/runs/box/storey/seed2/metrics.json";
  std::string text;
  {
    std::ifstream f(seed2);
    std::stringstream ss;
    ss << f.rdbuf();
    text = ss.str();
  }
  test::write_text(seed2, text.substr(0, text.size() / 2));
  test::write_text(out + "/runs/box/storey/seed3.partial/metrics.json", "{");

  const auto res = fake.runner(out, 1).run(specs);
  const auto calls = fake.call_lines();
  ASSERT_EQ(calls.size(), 6u + 4u);  // seed 2 of storey + the three refused
  EXPECT_EQ(calls[6], "storey full 2");
  EXPECT_TRUE(res[0].resumed);
  EXPECT_FALSE(res[1].resumed);
  EXPECT_TRUE(res[2].resumed);
  for (size_t i = 0; i < 3; ++i) EXPECT_EQ(res[i].status, RunStatus::finished);
  EXPECT_EQ(res[0].exit_code, 0);  // from the eval.json kept in the folder
  EXPECT_EQ(res[3].status, RunStatus::failed);

  // Everything finished: a third invocation runs only the failed ones.
  fake.runner(out).run(expand_matrix({{{"box"}, {"storey"}, {"full"}}}, {1, 2, 3}));
  EXPECT_EQ(fake.call_lines().size(), 10u);
}

TEST(Runner, ASignalledOrMissingChildIsAFailedRunNotAnAbort) {
  FakeStorey fake;
  const std::string out = fake.dir + "/eval";
  auto specs = expand_matrix({{{"box"}, {"crash", "storey"}, {"full"}}}, {1});
  const auto res = fake.runner(out).run(specs);
  ASSERT_EQ(res.size(), 2u);
  EXPECT_EQ(res[0].status, RunStatus::failed);
  EXPECT_EQ(res[0].reason.rfind("killed by signal 11", 0), 0u) << res[0].reason;
  EXPECT_EQ(res[1].status, RunStatus::finished);

  const auto missing =
      Runner({fake.dir + "/no-such-storey", 1, out + "2", TimeLimits{30, {}}, "", nullptr})
          .run(specs);
  EXPECT_EQ(missing[0].status, RunStatus::failed);
  EXPECT_NE(missing[0].reason.find("no-such-storey"), std::string::npos) << missing[0].reason;
}

TEST(Runner, AfterAStopRequestNothingNewStartsAndFinishedRunsStillCount) {
  FakeStorey fake;
  const std::string out = fake.dir + "/eval";
  fake.runner(out).run(expand_matrix({{{"box"}, {"storey"}, {"full"}}}, {1}));
  ASSERT_EQ(fake.call_lines().size(), 1u);
  Runner::request_stop();
  const auto res = fake.runner(out).run(expand_matrix({{{"box"}, {"storey"}, {"full"}}}, {1, 2}));
  Runner::clear_stop();
  EXPECT_EQ(fake.call_lines().size(), 1u);
  ASSERT_EQ(res.size(), 2u);
  EXPECT_EQ(res[0].status, RunStatus::finished);
  EXPECT_TRUE(res[0].resumed);
  EXPECT_EQ(res[1].status, RunStatus::not_run);
  EXPECT_FALSE(fs::exists(out + "/runs/box/storey/seed2"));
}

TEST(Runner, FormatDuration) {
  EXPECT_EQ(format_duration(12.2), "12s");
  EXPECT_EQ(format_duration(245), "4m05s");
  EXPECT_EQ(format_duration(3720), "1h02m");
}

}  // namespace
}  // namespace storey::tools::eval

namespace storey::tools::eval {
namespace {

TEST(RunRecord, LastSimulatedTimeReadsTheChildsProgressLines) {
  const std::string dir = test::fresh_dir("simtime");
  const std::string log = dir + "/log.txt";
  EXPECT_DOUBLE_EQ(last_simulated_time(log), -1.0);  // no file yet
  test::write_text(log, "storey sim: scene office, sensor vlp16, seed 1, time limit 60 s\n");
  EXPECT_DOUBLE_EQ(last_simulated_time(log), -1.0);
  std::string text = "storey sim: scene office\n";
  for (int i = 1; i <= 400; ++i) {  // longer than the 4 KiB tail that is read
    char b[128];
    std::snprintf(b, sizeof b, "[sim %7.1f s] coverage %5.1f %%  floor 0  nodes 12\n", 5.0 * i,
                  0.1 * i);
    text += b;
  }
  test::write_text(log, text);
  EXPECT_DOUBLE_EQ(last_simulated_time(log), 2000.0);
  EXPECT_EQ(last_line(log).rfind("[sim  2000.0 s]", 0), 0u);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace storey::tools::eval
