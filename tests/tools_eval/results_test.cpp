// Aggregation on fixture metrics.json files (written by tools/sim's own writer): statistics,
// the tables' cells, failures as "n/a (k of N failed)", CSV/JSON, curves and the PNG.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "test_util.hpp"
#include "tools/eval/coverage_plot.hpp"
#include "tools/eval/json.hpp"
#include "tools/eval/results.hpp"

namespace storey::tools::eval {
namespace {

namespace fs = std::filesystem;

std::string slurp(const std::string& path) {
  std::ifstream f(path);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

TEST(Results, StatIsMeanAndSampleStd) {
  const Stat s = stat_of({100, 110, 120});
  EXPECT_EQ(s.n, 3u);
  EXPECT_DOUBLE_EQ(s.mean, 110.0);
  EXPECT_DOUBLE_EQ(s.std, 10.0);
  EXPECT_DOUBLE_EQ(stat_of({7}).std, 0.0);
  EXPECT_EQ(stat_of({}).n, 0u);
  EXPECT_EQ(format_stat(s, 0, "-"), "110 ± 10");
  EXPECT_EQ(format_stat(stat_of({1.25, 1.35}), 2, "-"), "1.30 ± 0.07");
  EXPECT_EQ(format_stat(Stat{}, 0, "none"), "none");
}

// Table II's per-floor times, as the paper's: the robot's time on the floor until it was explored,
// from tracking.csv; the stair transitions and a visit to the other floor are left out.
TEST(Results, FloorTimeIsTheTimeOnTheFloorFromTrackingCsv) {
  const std::string dir = test::fresh_dir("onfloor");
  test::write_run(dir, test::fixture_metrics(600, 470, 271, 495), "exploration complete");
  auto r = read_metrics_json(dir + "/metrics.json", nullptr);
  ASSERT_TRUE(r);
  EXPECT_FALSE(add_time_on_floor(dir + "/none.csv", *r));
  EXPECT_TRUE(std::isnan(r->per_floor[0].time_on_floor_s));
  EXPECT_DOUBLE_EQ(floor_time(*r, 1), 224.0);  // without tracking: from the 1st floor's 90 %
  // Floor 0 until 200 s, up (10 s), floor 1 until 250 s, down (10 s), floor 0 until 300 s, up
  // (20 s), floor 1 to the end; 10 Hz.
  std::ostringstream csv;
  csv << "t_s,x_m,y_m,z_m,yaw_deg\n";
  for (int i = 0; i <= 6000; ++i) {
    const double t = 0.1 * i;
    const bool up = (t > 200 && t < 210) || (t > 250 && t < 260) || (t > 300 && t < 320);
    const double z = up ? 1.5 : ((t >= 210 && t <= 250) || t >= 320 ? 3.0 : 0.0);
    csv << t << ",1.0,2.0," << z << ",0\n";
  }
  test::write_text(dir + "/tracking.csv", csv.str());
  ASSERT_TRUE(add_time_on_floor(dir + "/tracking.csv", *r));
  EXPECT_NEAR(r->per_floor[0].time_on_floor_s, 200.0 + 11.0, 0.25);  // [0, 271]
  EXPECT_NEAR(r->per_floor[1].time_on_floor_s, 40.0 + 175.0, 0.25);  // [0, 495]
  EXPECT_NEAR(floor_time(*r, 0), 211.0, 0.25);
  EXPECT_NEAR(floor_time(*r, 1), 215.0, 0.25);
  // load_outcome reads it with the record.
  const RunOutcome o = load_outcome(RunSpec{}, dir);
  ASSERT_EQ(o.status, RunStatus::finished);
  EXPECT_NEAR(o.metrics.per_floor[1].time_on_floor_s, 215.0, 0.25);
  // The runner's eval.json keeps them: a copy of the record without tracking.csv (an archive
  // such as docs/eval/) loads the same figures.
  write_eval_record(o, dir, {"storey", "sim"});
  const std::string kept = test::fresh_dir("onfloor_kept");
  for (const char* f : {"metrics.json", "eval.json", "report.md"})
    fs::copy_file(dir + "/" + f, kept + "/" + f);
  const RunOutcome k = load_outcome(RunSpec{}, kept);
  ASSERT_EQ(k.status, RunStatus::finished);
  EXPECT_NEAR(k.metrics.per_floor[0].time_on_floor_s, 211.0, 0.25);
  EXPECT_NEAR(k.metrics.per_floor[1].time_on_floor_s, 215.0, 0.25);
}

TEST(Results, ReadsTheSimulatorsMetricsJson) {
  const std::string dir = test::fresh_dir("read");
  sim::RunMetrics m = test::fixture_metrics(530, 470, 271, 495);
  m.collisions = 1;
  m.walking_time_s = 321.5;
  m.latency.push_back({"map", 1.0, 2.0, 3.0, 4});
  test::write_run(dir, m, "exploration complete at 530.0 s");
  std::string err;
  const auto r = read_metrics_json(dir + "/metrics.json", &err);
  ASSERT_TRUE(r) << err;
  EXPECT_TRUE(r->success);
  EXPECT_EQ(r->floors_total, 2);
  EXPECT_DOUBLE_EQ(r->exploration_time_s, 530.0);
  EXPECT_DOUBLE_EQ(r->trajectory_length_m, 470.0);
  EXPECT_DOUBLE_EQ(r->occupied_volume_m3, 600.0);
  ASSERT_EQ(r->per_floor.size(), 2u);
  EXPECT_DOUBLE_EQ(r->per_floor[1].time_s, 495.0);
  EXPECT_DOUBLE_EQ(r->collisions, 1.0);
  EXPECT_DOUBLE_EQ(r->walking_time_s, 321.5);
  ASSERT_EQ(r->coverage_over_time.size(), 3u);
  EXPECT_DOUBLE_EQ(r->coverage_over_time[1].first, 265.0);
  EXPECT_DOUBLE_EQ(floor_time(*r, 0), 271.0);
  EXPECT_DOUBLE_EQ(floor_time(*r, 1), 224.0);
  EXPECT_EQ(read_report_outcome(dir + "/report.md"), "exploration complete at 530.0 s");

  // Cut anywhere, the file is not complete; a missing field is named.
  const std::string text = slurp(dir + "/metrics.json");
  for (size_t cut : {size_t(1), text.size() / 3, text.size() - 3}) {
    test::write_text(dir + "/cut.json", text.substr(0, cut));
    EXPECT_FALSE(read_metrics_json(dir + "/cut.json", &err)) << cut;
    EXPECT_NE(err.find("cut.json"), std::string::npos) << err;
  }
  std::string no_dist = text;
  no_dist.replace(no_dist.find("\"trajectory_length_m\""), 5, "\"xxxx");
  test::write_text(dir + "/nodist.json", no_dist);
  EXPECT_FALSE(read_metrics_json(dir + "/nodist.json", &err));
  EXPECT_NE(err.find("trajectory_length_m"), std::string::npos) << err;
  fs::remove_all(dir);
}

TEST(Results, JsonParserRejectsGarbageAndKeepsStrings) {
  JsonValue v;
  std::string err;
  EXPECT_FALSE(parse_json("{\"a\": [1, 2", v, &err));
  EXPECT_NE(err.find("unexpected end"), std::string::npos);
  EXPECT_FALSE(parse_json("{\"a\": 1} x", v, &err));
  EXPECT_FALSE(parse_json(std::string(200, '['), v, &err));
  ASSERT_TRUE(parse_json(R"({"s": "a\"b\\n\u00e9", "n": -1.5e2, "t": true, "z": null})", v, &err))
      << err;
  EXPECT_EQ(v.find("s")->string(), "a\"b\\n\xc3\xa9");
  EXPECT_DOUBLE_EQ(v.find("n")->number(), -150.0);
  JsonValue q;
  ASSERT_TRUE(parse_json(json_quote("x\"y\n\x01"), q, &err)) << err;
  EXPECT_EQ(q.string(), "x\"y\n\x01");
}

// Three scenes' worth of fixture runs: storey on "two" (3 seeds), tare-like failing all seeds,
// fael-like failing one of three, and maze ablations.
struct Fixture {
  std::string out = test::fresh_dir("results");
  std::vector<RunOutcome> outcomes;

  void add(const RunSpec& s, const sim::RunMetrics* m, const std::string& fail_reason = "") {
    const std::string dir = out + "/" + s.rel_dir();
    if (m) {
      test::write_run(dir, *m, "exploration complete");
    } else {
      fs::create_directories(dir);
      RunOutcome f;
      f.spec = s;
      f.status = RunStatus::failed;
      f.reason = fail_reason;
      f.exit_code = 2;
      write_eval_record(f, dir, {"storey", "sim"});
    }
    outcomes.push_back(load_outcome(s, dir));
  }
  Fixture() {
    const double t[] = {500, 530, 560}, f1[] = {260, 270, 280}, f2[] = {470, 490, 510};
    for (uint64_t k = 0; k < 3; ++k) {
      auto m = test::fixture_metrics(t[k], 400 + 10.0 * double(k), f1[k], f2[k]);
      m.commit = k == 2 ? "bbbbbbbbbbbb" : "aaaaaaaaaaaa";  // a matrix resumed on newer code
      add({"two", "storey", "", k + 1}, &m);
    }
    for (uint64_t k = 0; k < 3; ++k)
      add({"two", "tare-like", "", k + 1}, nullptr,
          "storey sim: --method tare-like: not available yet");
    for (uint64_t k = 0; k < 3; ++k) {
      const auto m = test::fixture_metrics(300 + 20.0 * double(k), 200, 250, -1);
      if (k == 1)
        add({"two", "fael-like", "", k + 1}, nullptr, "killed by signal 9");
      else
        add({"two", "fael-like", "", k + 1}, &m);
    }
    const auto full = test::fixture_metrics(250, 220, 240, 480, 628);
    const auto notent = test::fixture_metrics(330, 295, 320, 560, 617);
    add({"maze", "storey", "", 1}, &full);
    add({"maze", "storey", "no-tentative", 1}, &notent);
    add({"maze", "storey", "no-prior", 1}, &notent);
    add({"maze", "storey", "odd-one", 1}, &notent);
  }
  ~Fixture() { fs::remove_all(out); }
};

TEST(Results, MarkdownTablesShapedLikeThePapers) {
  Fixture fx;
  ResultsInput in{fx.outcomes, "storey-eval --test", {{"two", "coverage_two.png"}}};
  const std::string md = results_markdown(in);
  // Table I: mean ± std over seeds; all floors explored in every seed.
  EXPECT_NE(
      md.find(
          "| two | storey | 3/3 | Yes | 1+2 | done 3 | 530 ± 30 | 410 ± 10 | 250 ± 0 | 600 ± 0 | "
          "94.0 ± 0.0 | 0 / 0 |"),
      std::string::npos)
      << md;
  // The commits the finished runs were built from, and a warning when they differ (the other
  // fixture runs carry none).
  EXPECT_NE(md.find("Built from commits `aaaaaaaaaaaa` (2 runs), `bbbbbbbbbbbb` (1 run), `not "
                    "recorded` (6 runs): **runs from different code are mixed**."),
            std::string::npos)
      << md;
  // All failed: n/a with the count, in every metric cell.
  EXPECT_NE(
      md.find("| two | tare-like | 0/3 (3 failed) | n/a | n/a | n/a | n/a (3 of 3 failed) | n/a (3 "
              "of 3 failed) |"),
      std::string::npos)
      << md;
  // One of three failed: the mean over the two finished; floors explored: the first only.
  EXPECT_NE(md.find("| two | fael-like | 2/3 (1 failed) | No | 1 | done 2 | 320 ± 28 |"),
            std::string::npos)
      << md;
  // Table II: floor 1 270 ± 10, floor 2 (from floor 1 done) 220 ± 10, reduction 1 - 220/270.
  EXPECT_NE(md.find("| two | 3/3 | 270.0 ± 10.0 | 220.0 ± 10.0 | 18.5 % | 95.0 ± 0.0 | 93.0 ± "
                    "0.0 |"),
            std::string::npos)
      << md;
  // Tables III and IV: maze ablations with the paper's labels, full first.
  const size_t t3 = md.find(
      "## Table III: ablation on reachable graph and frontier detection "
      "(maze, storey)");
  ASSERT_NE(t3, std::string::npos) << md;
  EXPECT_NE(
      md.find("| Full (`full`) | 1/1 | done 1 | 250 ± 0 | 220 ± 0 | 628 ± 0 | 240.0 ± 0.0 |", t3),
      std::string::npos)
      << md;
  EXPECT_NE(
      md.find(
          "| w/o tentative (`no-tentative`) | 1/1 | done 1 | 330 ± 0 | 295 ± 0 | 617 ± 0 | 320.0",
          t3),
      std::string::npos)
      << md;
  const size_t t4 = md.find("## Table IV: ablation on the cross-floor structural prior (maze");
  ASSERT_NE(t4, std::string::npos) << md;
  EXPECT_NE(
      md.find("| w/o prior (`no-prior`) | 1/1 | done 1 | 330 ± 0 | 295 ± 0 | 617 ± 0 | 240.0 ± 0.0",
              t4),
      std::string::npos)
      << md;
  EXPECT_NE(md.find("| maze | storey-odd-one | 1/1 |"), std::string::npos) << md;
  EXPECT_NE(md.find("![two](coverage_two.png)"), std::string::npos);
  EXPECT_NE(md.find("| two | tare-like | 3 of 3 | storey sim: --method tare-like: not available "
                    "yet |"),
            std::string::npos)
      << md;
  EXPECT_NE(md.find("| two | fael-like | 1 of 3 | killed by signal 9 |"), std::string::npos);
}

TEST(Results, FootnoteNamesTheTimeLimitsTheRunsHad) {
  Fixture fx;
  // The fixture's runs carry no eval.json command: no line.
  EXPECT_EQ(results_markdown({fx.outcomes, "x", {}}).find("Time limits"), std::string::npos);
  std::vector<RunOutcome> o = fx.outcomes;
  for (auto& r : o) r.time_limit_s = 1800;
  o[0].time_limit_s = 3000;  // two/storey mixed; failed runs (two/tare-like) are not counted
  for (auto& r : o)
    if (r.spec.scene == "maze" && r.spec.ablation == "no-prior") r.time_limit_s = 900;
  for (auto& r : o)
    if (r.spec.method == "tare-like") r.time_limit_s = 60;
  EXPECT_NE(results_markdown({o, "x", {}})
                .find("Time limits (each run's --time-limit): 1800 s; two/storey 1800/3000 s; "
                      "maze/storey-no-prior 900 s."),
            std::string::npos)
      << results_markdown({o, "x", {}});
}

TEST(Results, CsvHasOneRowPerRunAndJsonParses) {
  Fixture fx;
  const std::string csv = results_csv(fx.outcomes);
  std::istringstream ss(csv);
  std::vector<std::string> lines;
  for (std::string l; std::getline(ss, l);) lines.push_back(l);
  ASSERT_EQ(lines.size(), 1u + fx.outcomes.size());
  EXPECT_EQ(lines[0].rfind("scene,method,ablation,seed,status,", 0), 0u);
  EXPECT_NE(lines[0].find(",floor2_time_s,floor2_coverage,"), std::string::npos);
  EXPECT_NE(lines[0].find(",safety_stops,walking_time_s,reason,"), std::string::npos);
  EXPECT_EQ(lines[1].rfind("two,storey,full,1,finished,0,,0.0,1,2,2,500.000,400.000,", 0), 0u)
      << lines[1];
  EXPECT_EQ(lines[4].rfind("two,tare-like,full,1,failed,0,2,", 0), 0u) << lines[4];
  EXPECT_NE(lines[4].find("not available yet"), std::string::npos);

  const std::string js = results_json({fx.outcomes, "cmd", {}});
  JsonValue j;
  std::string err;
  ASSERT_TRUE(parse_json(js, j, &err)) << err << "\n" << js;
  ASSERT_EQ(j.find("runs")->array().size(), fx.outcomes.size());
  const JsonValue& g0 = j.find("groups")->array().at(0);
  EXPECT_EQ(g0.find("method")->string(), "storey");
  EXPECT_DOUBLE_EQ(g0.find("exploration_time_s")->find("mean")->number(), 530.0);
  EXPECT_DOUBLE_EQ(g0.find("exploration_time_s")->find("std")->number(), 30.0);
  EXPECT_DOUBLE_EQ(g0.find("floor_time_s")->array().at(1).find("mean")->number(), 220.0);
  const JsonValue& g1 = j.find("groups")->array().at(1);
  EXPECT_EQ(g1.find("failed")->number(), 3.0);
  EXPECT_TRUE(g1.find("exploration_time_s")->find("mean")->kind() == JsonValue::Kind::null);
}

TEST(Results, MeanCoverageCurveHoldsSamplesAndFinalValues) {
  RunOutcome a, b, failed;
  a.status = b.status = RunStatus::finished;
  failed.status = RunStatus::failed;
  a.metrics.coverage_over_time = {{0, 0.0}, {10, 0.5}, {20, 0.9}};
  b.metrics.coverage_over_time = {{0, 0.1}, {5, 0.3}};  // ended at 5 s, keeps 0.3
  failed.metrics.coverage_over_time = {{0, 1.0}};
  const CoverageCurve c = mean_coverage_curve({&a, &b, &failed}, 5.0, 20.0);
  EXPECT_EQ(c.runs, 2u);
  ASSERT_EQ(c.t.size(), 5u);
  EXPECT_DOUBLE_EQ(c.t[4], 20.0);
  EXPECT_DOUBLE_EQ(c.mean[0], 0.05);
  EXPECT_DOUBLE_EQ(c.mean[1], 0.15);  // a: 0.0 (held), b: 0.3
  EXPECT_DOUBLE_EQ(c.mean[2], 0.40);  // a: 0.5
  EXPECT_DOUBLE_EQ(c.mean[3], 0.40);
  EXPECT_DOUBLE_EQ(c.mean[4], 0.60);  // a: 0.9
}

TEST(Results, WritesEveryOutputAndAPngPerScene) {
  Fixture fx;
  const auto files = write_results(fx.out, fx.outcomes, "storey-eval --test");
  for (const char* name :
       {"results.md", "results.csv", "results.json", "coverage_two.png", "coverage_maze.png"}) {
    const std::string p = fx.out + "/" + name;
    ASSERT_TRUE(fs::exists(p)) << p;
    EXPECT_GT(fs::file_size(p), 100u) << p;
  }
  EXPECT_EQ(slurp(fx.out + "/coverage_two.png").substr(1, 3), "PNG");
  EXPECT_NE(slurp(fx.out + "/results.md").find("Command: `storey-eval --test`"), std::string::npos);
}

}  // namespace
}  // namespace storey::tools::eval
