// The Parameters loader: shipped files, every error kind with its message, cross-field rules,
// file errors and include layering (real temporary files).
#include "config/parameters.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace storey::config {
namespace {

namespace fs = std::filesystem;

const std::string kConfigDir = std::string(STOREY_SOURCE_DIR) + "/config/";

// The two required values, appended after the text under test so its line numbers stay put.
const std::string kRequired = "\nsensor:\n  type: vlp16\nlink:\n  transport: sim\n";

std::vector<std::string> messages(const Result& r) {
  std::vector<std::string> out;
  for (const ConfigError& e : r.errors) out.push_back(e.to_string());
  return out;
}

std::string joined(const Result& r) {
  std::string s;
  for (const std::string& m : messages(r)) s += m + "\n";
  return s;
}

// A fresh directory per test, removed afterwards.
class TempDir {
 public:
  TempDir() {
    static int counter = 0;
    dir_ = fs::temp_directory_path() /
           ("storey_config_test_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  std::string write(const std::string& name, const std::string& text) const {
    const fs::path p = dir_ / name;
    fs::create_directories(p.parent_path());
    std::ofstream(p) << text;
    return p.string();
  }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }

 private:
  fs::path dir_;
};

// ---- shipped files ---------------------------------------------------------------------------

TEST(ConfigFiles, DefaultLoadsAndMatchesTheDocumentedDefaults) {
  const Result r = load(kConfigDir + "default.yaml");
  ASSERT_TRUE(r.ok()) << joined(r);
  const Parameters d;  // the structs' documented defaults (DESIGN.md §4)
  const Parameters& p = r.params;
  EXPECT_DOUBLE_EQ(p.map.voxel_size_m, 0.1);
  EXPECT_EQ(p.map.n_min, 5);
  EXPECT_DOUBLE_EQ(p.graph.r_e_m, 1.0);
  EXPECT_DOUBLE_EQ(p.graph.node_clearance_m, 0.5);
  EXPECT_EQ(p.graph.k_max, 8);
  EXPECT_NEAR(p.graph.alpha_min_rad, d.graph.alpha_min_rad, 1e-12);
  EXPECT_DOUBLE_EQ(p.graph.rho_min, 0.3);
  EXPECT_EQ(p.graph.probes, 12);
  EXPECT_EQ(p.graph.theta_min, 2);
  EXPECT_DOUBLE_EQ(p.plan.r_z_m, 6.0);
  EXPECT_EQ(p.plan.window_w, 4);
  EXPECT_EQ(p.plan.max_candidates_k, 8);
  EXPECT_DOUBLE_EQ(p.robot.max_speed_mps, 1.0);
  EXPECT_DOUBLE_EQ(p.robot.max_yaw_rate_rps, 1.0);
  EXPECT_DOUBLE_EQ(p.robot.body_length_m, 0.70);
  EXPECT_DOUBLE_EQ(p.robot.body_width_m, 0.31);
  EXPECT_DOUBLE_EQ(p.robot.body_height_m, 0.40);
  EXPECT_DOUBLE_EQ(p.robot.step_height_m, 0.18);
  EXPECT_NEAR(p.robot.max_slope_rad, d.robot.max_slope_rad, 1e-12);
  // The file and the struct defaults agree everywhere else too.
  EXPECT_FLOAT_EQ(p.map.log_odds_hit, d.map.log_odds_hit);
  EXPECT_DOUBLE_EQ(p.map.tau_c, d.map.tau_c);
  EXPECT_EQ(p.plan.zone_capacity, d.plan.zone_capacity);
  EXPECT_DOUBLE_EQ(p.safety.lidar_stale_s, 0.3);
  EXPECT_DOUBLE_EQ(p.safety.pose_stale_s, 0.1);
  EXPECT_DOUBLE_EQ(p.rates.map.rate_hz, 10.0);
  EXPECT_DOUBLE_EQ(p.rates.plan.rate_hz, 2.0);
  EXPECT_DOUBLE_EQ(p.rates.control.rate_hz, 50.0);
  EXPECT_DOUBLE_EQ(p.rates.watchdog.rate_hz, 10.0);
  EXPECT_DOUBLE_EQ(p.rates.telemetry.rate_hz, 1.0);
  EXPECT_DOUBLE_EQ(p.rates.ingest.rate_hz, 0.0);
  EXPECT_EQ(p.sensor.type, SensorType::kVlp16);
  EXPECT_EQ(p.link.transport, LinkTransport::kSim);
  EXPECT_FALSE(p.realtime.sched_fifo);
}

TEST(ConfigFiles, DefaultSetsEveryParameter) {
  const Result r = load(kConfigDir + "default.yaml");
  ASSERT_TRUE(r.ok()) << joined(r);
  EXPECT_GT(r.schema_keys.size(), 90u);
  for (const std::string& key : r.schema_keys) {
    EXPECT_EQ(r.origins.count(key), 1u) << "default.yaml does not set " << key;
  }
}

TEST(ConfigFiles, Go2Mid360OverridesTheDefaults) {
  const Result r = load(kConfigDir + "go2_mid360.yaml");
  ASSERT_TRUE(r.ok()) << joined(r);
  ASSERT_EQ(r.files.size(), 2u);
  EXPECT_EQ(fs::path(r.files[0]).filename(), "default.yaml");
  EXPECT_EQ(fs::path(r.files[1]).filename(), "go2_mid360.yaml");
  const Parameters& p = r.params;
  EXPECT_EQ(p.sensor.type, SensorType::kMid360);
  EXPECT_EQ(p.sensor.data_port, 56301);
  EXPECT_EQ(p.link.transport, LinkTransport::kDds);
  EXPECT_EQ(p.link.dds.interface, "eth0");
  EXPECT_TRUE(p.realtime.sched_fifo);
  EXPECT_TRUE(p.realtime.mlockall);
  EXPECT_TRUE(p.realtime.cpu_pinning);
  EXPECT_EQ(p.rates.control.cpu, 2);
  // Not overridden: still the default file's values.
  EXPECT_DOUBLE_EQ(p.rates.control.rate_hz, 50.0);
  EXPECT_EQ(p.rates.control.priority, 90);
  EXPECT_DOUBLE_EQ(p.map.voxel_size_m, 0.1);
  EXPECT_EQ(fs::path(r.origins.at("map.voxel_size_m").file).filename(), "default.yaml");
  EXPECT_EQ(fs::path(r.origins.at("sensor.type").file).filename(), "go2_mid360.yaml");
}

TEST(ConfigFiles, HilUsesUdpAndLoopback) {
  const Result r = load(kConfigDir + "hil.yaml");
  ASSERT_TRUE(r.ok()) << joined(r);
  const Parameters& p = r.params;
  EXPECT_EQ(p.sensor.type, SensorType::kVlp16);
  EXPECT_EQ(p.sensor.sensor_address, "127.0.0.1");
  EXPECT_EQ(p.sensor.host_address, "127.0.0.1");
  EXPECT_EQ(p.link.transport, LinkTransport::kUdp);
  EXPECT_EQ(p.link.udp.robot_address, "127.0.0.1");
  EXPECT_NE(p.link.udp.robot_port, p.link.udp.local_port);
  EXPECT_FALSE(p.realtime.sched_fifo);
}

// ---- error kinds -----------------------------------------------------------------------------

// The experimental blind stair climb is one switch; the map and the graph read it too.
TEST(ConfigFiles, ClimbBlindSetsTheMapAndGraphSides) {
  const Result off = load_string(kRequired, "t.yaml");
  ASSERT_TRUE(off.ok());
  EXPECT_FALSE(off.params.plan.climb_blind);
  EXPECT_FALSE(off.params.map.pool_short_risers);
  EXPECT_FALSE(off.params.graph.climb_frontiers);
  const Result on = load_string("plan:\n  climb_blind: true\n" + kRequired, "t.yaml");
  ASSERT_TRUE(on.ok());
  EXPECT_TRUE(on.params.plan.climb_blind);
  EXPECT_TRUE(on.params.map.pool_short_risers);
  EXPECT_TRUE(on.params.graph.climb_frontiers);
}

TEST(ConfigErrors, UnknownKeyNamesFileKeyLineAndSuggestion) {
  const Result r = load_string(
      "# comment\n"
      "map:\n"
      "  voxel_size_m: 0.1\n"
      "  voxle_size_m: 0.2\n" +
          kRequired,
      "config/test.yaml");
  ASSERT_EQ(messages(r).size(), 1u) << joined(r);
  EXPECT_EQ(messages(r)[0],
            "config/test.yaml:4: map.voxle_size_m: unknown key (did you mean 'voxel_size_m'?)");
}

TEST(ConfigErrors, UnknownSectionSuggestsTheSection) {
  const Result r = load_string("grpah:\n  k_max: 4\n" + kRequired, "t.yaml");
  ASSERT_EQ(messages(r).size(), 1u) << joined(r);
  EXPECT_EQ(messages(r)[0], "t.yaml:1: grpah: unknown key (did you mean 'graph'?)");
}

TEST(ConfigErrors, WrongType) {
  const Result r = load_string("graph:\n  k_max: many\n  use_c_sur: 1.5\n" + kRequired, "t.yaml");
  ASSERT_EQ(messages(r).size(), 2u) << joined(r);
  EXPECT_EQ(messages(r)[0], "t.yaml:2: graph.k_max: expected an integer, got 'many'");
  EXPECT_EQ(messages(r)[1], "t.yaml:3: graph.use_c_sur: expected true or false, got '1.5'");
}

TEST(ConfigErrors, MissingRequired) {
  const Result r = load_string("sensor:\n  min_range_m: 0.5\n", "t.yaml");
  ASSERT_EQ(messages(r).size(), 2u) << joined(r);
  // sensor: present -> its line; link: absent -> the whole file.
  EXPECT_EQ(messages(r)[0], "t.yaml: link.transport: missing required value");
  EXPECT_EQ(messages(r)[1], "t.yaml:1: sensor.type: missing required value");
}

TEST(ConfigErrors, OutOfRange) {
  const Result r = load_string(
      "map:\n  voxel_size_m: 2.5\ngraph:\n  alpha_min_deg: 190\n" + kRequired, "t.yaml");
  ASSERT_EQ(messages(r).size(), 2u) << joined(r);
  EXPECT_EQ(messages(r)[0], "t.yaml:2: map.voxel_size_m: 2.5 is out of range [0.01, 1]");
  EXPECT_EQ(messages(r)[1], "t.yaml:4: graph.alpha_min_deg: 190 is out of range [0, 180]");
}

TEST(ConfigErrors, BadEnum) {
  const Result r = load_string("sensor:\n  type: vlp61\nlink:\n  transport: ros\n", "t.yaml");
  ASSERT_EQ(messages(r).size(), 2u) << joined(r);
  EXPECT_EQ(messages(r)[0],
            "t.yaml:2: sensor.type: 'vlp61' is not one of vlp16, mid360 (did you mean 'vlp16'?)");
  EXPECT_EQ(messages(r)[1], "t.yaml:4: link.transport: 'ros' is not one of dds, udp, can, sim");
}

TEST(ConfigErrors, BadAddressAndList) {
  const Result r = load_string(
      "sensor:\n"
      "  type: mid360\n"
      "  host_address: 300.1.2.3\n"
      "  mounting:\n"
      "    rpy_deg: [0, 0]\n"
      "link:\n"
      "  transport: sim\n",
      "t.yaml");
  ASSERT_EQ(messages(r).size(), 2u) << joined(r);
  // Sorted by line.
  EXPECT_EQ(messages(r)[0],
            "t.yaml:3: sensor.host_address: '300.1.2.3' is not an IPv4 address (a.b.c.d)");
  EXPECT_EQ(messages(r)[1],
            "t.yaml:5: sensor.mounting.rpy_deg: expected a list of 3 numbers, got 2 elements");
}

TEST(ConfigErrors, CrossFieldNamesTheKeyTheUserWrote) {
  const Result r = load_string(
      "graph:\n"
      "  node_clearance_m: 1.5\n"
      "sensor:\n"
      "  type: vlp16\n"
      "  min_range_m: 5\n"
      "  max_range_m: 4\n"
      "rates:\n"
      "  control: {rate_hz: 50, budget_us: 30000}\n"
      "link:\n"
      "  transport: sim\n"
      "safety:\n"
      "  turn_on_reference_full_m: 0.2\n"
      "  turn_on_reference_zero_m: 0.1\n",
      "t.yaml");
  ASSERT_EQ(messages(r).size(), 4u) << joined(r);
  EXPECT_EQ(messages(r)[0],
            "t.yaml:2: graph.node_clearance_m: graph.r_e_m = 1 must be greater than "
            "graph.node_clearance_m = 1.5");
  EXPECT_EQ(messages(r)[1],
            "t.yaml:6: sensor.max_range_m: sensor.max_range_m = 4 must be greater than "
            "sensor.min_range_m = 5");
  EXPECT_EQ(messages(r)[2],
            "t.yaml:8: rates.control.budget_us: rates.control.budget_us = 30000 exceeds the "
            "task period of 20000 us (50 Hz)");
  EXPECT_EQ(messages(r)[3],
            "t.yaml:13: safety.turn_on_reference_zero_m: safety.turn_on_reference_zero_m = 0.1 "
            "must be greater than safety.turn_on_reference_full_m = 0.2");
}

TEST(ConfigErrors, CrossFieldUdpPortClash) {
  const Result r = load_string(
      "sensor:\n  type: vlp16\n  data_port: 17002\n"
      "link:\n  transport: udp\n  udp:\n    robot_port: 17002\n",
      "t.yaml");
  ASSERT_EQ(messages(r).size(), 2u) << joined(r);
  EXPECT_EQ(messages(r)[0].rfind("t.yaml:3: sensor.data_port: link.udp.local_port = 17002", 0), 0u)
      << messages(r)[0];
  EXPECT_EQ(messages(r)[1].rfind("t.yaml:7: link.udp.robot_port: link.udp.local_port", 0), 0u)
      << messages(r)[1];
}

TEST(ConfigErrors, CrossFieldSkipsKeysThatAlreadyFailed) {
  // max_range_m failed its own check; no second, confusing cross-field error about it.
  const Result r = load_string(
      "sensor:\n  type: vlp16\n  max_range_m: fast\n"
      "link:\n  transport: sim\n",
      "t.yaml");
  ASSERT_EQ(messages(r).size(), 1u) << joined(r);
}

TEST(ConfigErrors, AllErrorsAreCollected) {
  const Result r = load_string(
      "robot:\n"
      "  max_sped_mps: 1\n"
      "  step_height_m: -1\n"
      "map:\n"
      "  n_min: 2.5\n"
      "  voxel_size_m:\n"
      "plan:\n"
      "  window_w: 4\n"
      "  window_w: 5\n"
      "sensor: 3\n",
      "t.yaml");
  const std::string all = joined(r);
  EXPECT_EQ(r.errors.size(), 8u) << all;
  EXPECT_NE(all.find("t.yaml:2: robot.max_sped_mps: unknown key (did you mean 'max_speed_mps'?)"),
            std::string::npos)
      << all;
  EXPECT_NE(all.find("t.yaml:3: robot.step_height_m: -1 is out of range [0, 0.5]"),
            std::string::npos);
  EXPECT_NE(all.find("t.yaml:5: map.n_min: expected an integer, got 2.5"), std::string::npos);
  EXPECT_NE(all.find("t.yaml:6: map.voxel_size_m: missing value"), std::string::npos);
  EXPECT_NE(all.find("t.yaml:9: plan.window_w: duplicate key (first given on line 8)"),
            std::string::npos);
  EXPECT_NE(all.find("t.yaml:10: sensor: expected a mapping, got '3'"), std::string::npos);
  EXPECT_NE(all.find("t.yaml:10: sensor.type: missing required value"), std::string::npos);
  EXPECT_NE(all.find("t.yaml: link.transport: missing required value"), std::string::npos);
}

TEST(ConfigErrors, MalformedYamlNamesItsLine) {
  const Result r = load_string("map:\n  voxel_size_m: 0.1\n n_min: 3\n", "t.yaml");
  ASSERT_EQ(messages(r).size(), 1u) << joined(r);
  EXPECT_EQ(messages(r)[0], "t.yaml:3: malformed YAML: end of map not found");
}

TEST(ConfigErrors, TopLevelMustBeAMapping) {
  const Result r = load_string("- map\n- graph\n", "t.yaml");
  ASSERT_EQ(messages(r).size(), 1u) << joined(r);
  EXPECT_EQ(messages(r)[0],
            "t.yaml:1: expected a mapping of sections (robot:, map:, ...) at the top level");
}

TEST(ConfigErrors, EmptyFileOnlyLacksTheRequiredValues) {
  const Result r = load_string("", "t.yaml");
  ASSERT_EQ(messages(r).size(), 2u) << joined(r);
}

// ---- files and layering ----------------------------------------------------------------------

TEST(ConfigLoad, UnreadableFile) {
  TempDir tmp;
  const std::string missing = tmp.path("missing.yaml");
  const Result r = load(missing);
  ASSERT_EQ(messages(r).size(), 1u) << joined(r);
  EXPECT_EQ(messages(r)[0], missing + ": cannot read file: No such file or directory");
  const Result d = load(tmp.path(""));
  ASSERT_EQ(messages(d).size(), 1u) << joined(d);
  EXPECT_NE(messages(d)[0].find("Is a directory"), std::string::npos);
}

TEST(ConfigLoad, MalformedFileOnDisk) {
  TempDir tmp;
  const std::string f = tmp.write("bad.yaml", "sensor:\n  type: [vlp16\n");
  const Result r = load(f);
  ASSERT_EQ(messages(r).size(), 1u) << joined(r);
  EXPECT_EQ(messages(r)[0].rfind(f + ":3: malformed YAML:", 0), 0u) << messages(r)[0];
}

TEST(ConfigLoad, IncludeOverridesOnlyWhatDiffers) {
  TempDir tmp;
  tmp.write("base/base.yaml", "map:\n  voxel_size_m: 0.2\n  n_min: 7\n" + kRequired);
  const std::string top =
      tmp.write("robot.yaml",
                "include: base/base.yaml\nmap:\n  voxel_size_m: 0.05\nsensor:\n  type: mid360\n");
  const Result r = load(top);
  ASSERT_TRUE(r.ok()) << joined(r);
  EXPECT_DOUBLE_EQ(r.params.map.voxel_size_m, 0.05);  // overridden
  EXPECT_EQ(r.params.map.n_min, 7);                   // from the base
  EXPECT_EQ(r.params.sensor.type, SensorType::kMid360);
  EXPECT_EQ(r.params.link.transport, LinkTransport::kSim);  // required, given by the base
  ASSERT_EQ(r.files.size(), 2u);
  EXPECT_EQ(r.files[0], tmp.path("base/base.yaml"));
  EXPECT_EQ(r.files[1], top);
}

TEST(ConfigLoad, ErrorsInAnIncludedFileNameThatFile) {
  TempDir tmp;
  const std::string base = tmp.write("base.yaml", "\n\ngraph:\n  k_mx: 4\n" + kRequired);
  const std::string top = tmp.write("top.yaml", "include: base.yaml\nmap:\n  voxel_size: 1\n");
  const Result r = load(top);
  ASSERT_EQ(messages(r).size(), 2u) << joined(r);
  EXPECT_EQ(messages(r)[0], base + ":4: graph.k_mx: unknown key (did you mean 'k_max'?)");
  EXPECT_EQ(messages(r)[1], top + ":3: map.voxel_size: unknown key (did you mean 'voxel_size_m'?)");
}

// A cross-field error names the key changed by the latest layer: that is what the user just
// wrote, even though the other key of the pair comes from the base file.
TEST(ConfigLoad, CrossFieldErrorPointsAtTheLatestLayer) {
  TempDir tmp;
  tmp.write("base.yaml", "sensor:\n  type: vlp16\n  max_range_m: 5\nlink:\n  transport: sim\n");
  const std::string top = tmp.write("top.yaml", "include: base.yaml\nsensor:\n  min_range_m: 8\n");
  const Result r = load(top);
  ASSERT_EQ(messages(r).size(), 1u) << joined(r);
  EXPECT_EQ(messages(r)[0], top +
                                ":3: sensor.min_range_m: sensor.max_range_m = 5 must be "
                                "greater than sensor.min_range_m = 8");
  // Both in the same layer: the first key of the rule is named.
  const std::string both =
      tmp.write("both.yaml", "include: base.yaml\nsensor:\n  min_range_m: 8\n  max_range_m: 6\n");
  const Result rb = load(both);
  ASSERT_EQ(messages(rb).size(), 1u) << joined(rb);
  EXPECT_EQ(messages(rb)[0].rfind(both + ":4: sensor.max_range_m:", 0), 0u) << messages(rb)[0];
}

TEST(ConfigLoad, IncludeListAppliesInOrder) {
  TempDir tmp;
  tmp.write("a.yaml", "map:\n  n_min: 3\n  voxel_size_m: 0.15\n");
  tmp.write("b.yaml", "map:\n  n_min: 4\n");
  const std::string top = tmp.write("top.yaml", "include: [a.yaml, b.yaml]\n" + kRequired);
  const Result r = load(top);
  ASSERT_TRUE(r.ok()) << joined(r);
  EXPECT_EQ(r.params.map.n_min, 4);
  EXPECT_DOUBLE_EQ(r.params.map.voxel_size_m, 0.15);
  EXPECT_EQ(r.files.size(), 3u);
}

TEST(ConfigLoad, MissingIncludeIsReportedAtTheIncludeLine) {
  TempDir tmp;
  const std::string top = tmp.write("top.yaml", "# robot\ninclude: nothere.yaml\n" + kRequired);
  const Result r = load(top);
  ASSERT_EQ(messages(r).size(), 1u) << joined(r);
  EXPECT_EQ(messages(r)[0], top + ":2: include: cannot read '" + tmp.path("nothere.yaml") +
                                "': No such file or directory");
}

TEST(ConfigLoad, IncludeCycleIsAnError) {
  TempDir tmp;
  const std::string a = tmp.write("a.yaml", "include: b.yaml\n" + kRequired);
  const std::string b = tmp.write("b.yaml", "include: a.yaml\n");
  const Result r = load(a);
  ASSERT_EQ(messages(r).size(), 1u) << joined(r);
  EXPECT_EQ(messages(r)[0], b + ":1: include: 'a.yaml' includes itself (include cycle)");
}

TEST(ConfigLoad, ShippedFileWithATypoFailsWithFileKeyAndLine) {
  // The acceptance case: copy default.yaml, misspell one key, load it.
  TempDir tmp;
  std::ifstream in(kConfigDir + "default.yaml");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::size_t at = text.find("  voxel_size_m:");
  ASSERT_NE(at, std::string::npos);
  const int line = 1 + static_cast<int>(std::count(text.begin(), text.begin() + at, '\n'));
  text.replace(at, 15, "  voxle_size_m:");
  const std::string f = tmp.write("default.yaml", text);
  const Result r = load(f);
  ASSERT_EQ(messages(r).size(), 1u) << joined(r);
  EXPECT_EQ(messages(r)[0], f + ":" + std::to_string(line) +
                                ": map.voxle_size_m: unknown key (did you mean 'voxel_size_m'?)");
}

}  // namespace
}  // namespace storey::config

namespace storey::config {
namespace {

// A field added to a core option struct must also be added to config/parameters.cpp and
// config/default.yaml (DefaultSetsEveryParameter then checks the file). This trips on the size
// change; update the figures here once both are done.
TEST(ConfigSchema, CoreOptionStructsAreFullyMapped) {
  EXPECT_EQ(sizeof(core::RobotModel), 80u) << "RobotModel changed: update the config schema";
  // MapOptions::pool_short_risers and GraphOptions::climb_frontiers / root_off_graph are set by
  // plan.climb_blind.
  EXPECT_EQ(sizeof(core::map::MapOptions), 152u) << "MapOptions changed: update the config schema";
  EXPECT_EQ(sizeof(core::graph::GraphOptions), 224u)
      << "GraphOptions changed: update the config schema";
  EXPECT_EQ(sizeof(core::plan::PlanOptions), 304u)
      << "PlanOptions changed: update the config schema";
}

}  // namespace
}  // namespace storey::config

namespace storey::config {
namespace {

// Bad input never crashes the loader: damaged copies of default.yaml (a byte removed, replaced
// or duplicated at spread positions) each load to either a valid result or named errors.
TEST(ConfigRobustness, DamagedDefaultNeverCrashesAndAlwaysExplains) {
  std::ifstream in(kConfigDir + "default.yaml");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_GT(text.size(), 1000u);
  const char kBytes[] = {':',  '-', '[', '{', '"', '\'', '\t', ' ',
                         '\n', '#', '&', '*', '!', 'x',  '9',  '\0'};
  int variants = 0, failed = 0;
  for (std::size_t pos = 0; pos < text.size(); pos += 61) {
    for (int kind = 0; kind < 3; ++kind) {
      std::string t = text;
      if (kind == 0) t.erase(pos, 1);
      if (kind == 1) t[pos] = kBytes[(pos / 61) % sizeof kBytes];
      if (kind == 2) t.insert(pos, 1, t[pos]);
      const Result r = load_string(t, "damaged.yaml");
      ++variants;
      if (r.ok()) continue;
      ++failed;
      for (const ConfigError& e : r.errors) {
        ASSERT_EQ(e.where.file, "damaged.yaml") << e.to_string();
        ASSERT_FALSE(e.message.empty());
      }
    }
  }
  EXPECT_GT(variants, 400);          // ~9 KB / 61 * 3
  EXPECT_GT(failed, variants / 10);  // the damage is noticed, not silently accepted
}

}  // namespace
}  // namespace storey::config

namespace storey::config {
namespace {

TEST(ConfigErrors, DdsDiscoveryAndPeerList) {
  const Result none = load_string(
      "sensor:\n  type: mid360\nlink:\n  transport: dds\n  dds:\n    allow_multicast: false\n",
      "t.yaml");
  ASSERT_EQ(messages(none).size(), 1u) << joined(none);
  EXPECT_EQ(messages(none)[0],
            "t.yaml:6: link.dds.allow_multicast: link.dds.peers is empty and "
            "link.dds.allow_multicast is false: no discovery");

  const Result bad = load_string(
      "sensor:\n  type: mid360\nlink:\n  transport: dds\n  dds:\n    allow_multicast: false\n"
      "    peers: [127.0.0.1, robot]\n",
      "t.yaml");
  ASSERT_EQ(messages(bad).size(), 1u) << joined(bad);
  EXPECT_EQ(messages(bad)[0],
            "t.yaml:7: link.dds.peers[1]: 'robot' is not an IPv4 address (a.b.c.d)");

  const Result ok = load_string(
      "sensor:\n  type: mid360\nlink:\n  transport: dds\n  dds:\n    allow_multicast: false\n"
      "    peers: [127.0.0.1]\n",
      "t.yaml");
  ASSERT_TRUE(ok.ok()) << joined(ok);
  ASSERT_EQ(ok.params.link.dds.peers.size(), 1u);
  EXPECT_EQ(ok.params.link.dds.peers[0], "127.0.0.1");
}

}  // namespace
}  // namespace storey::config
