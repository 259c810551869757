// The hardware-in-the-loop capture (tests/data/hil_vlp16_house.pcap, written by `storey run
// --record` against storey-sim) replays through the live ingestion path with zero drops.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "firmware/commands.hpp"

namespace {

namespace fs = std::filesystem;

long field(const std::string& json, const std::string& key) {
  std::smatch m;
  const std::regex re("\"" + key + "\": ([0-9]+)");
  return std::regex_search(json, m, re) ? std::stol(m[1]) : -1;
}

TEST(ReplayHilCapture, DecodesWithZeroDropsIntoWholeScans) {
  const fs::path out = fs::temp_directory_path() / "storey_replay_hil_capture";
  std::vector<std::string> args = {
      "replay", std::string(STOREY_SOURCE_DIR) + "/tests/data/hil_vlp16_house.pcap",
      "--fast", "--profile",
      "--out",  out.string()};
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  ASSERT_EQ(storey::firmware::cmd_replay(int(argv.size()), argv.data()), 0);
  std::ifstream f(out / "replay.json");
  std::stringstream ss;
  ss << f.rdbuf();
  const std::string j = ss.str();
  EXPECT_EQ(field(j, "packets"), 965);
  EXPECT_EQ(field(j, "accepted"), 965);
  EXPECT_EQ(field(j, "dropped"), 0);
  EXPECT_EQ(field(j, "points"), 965 * 384);  // every shot of the simulated house returns
  EXPECT_GE(field(j, "scans"), 12);          // 10 Hz for 1.28 s
  EXPECT_TRUE(fs::exists(out / "trace.json"));
  fs::remove_all(out);
}

}  // namespace
