// storey replay on the real VLP-16 capture: the verb's own output, end to end.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "firmware/commands.hpp"

namespace {

namespace fs = std::filesystem;

int run(std::vector<std::string> args) {
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  return storey::firmware::cmd_replay(static_cast<int>(argv.size()), argv.data());
}

std::string slurp(const fs::path& p) {
  std::ifstream f(p);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

TEST(Replay, RealVlp16CaptureWritesCountsAndScans) {
  const fs::path out = fs::temp_directory_path() / "storey_replay_test";
  fs::remove_all(out);
  const std::string capture = std::string(STOREY_SOURCE_DIR) + "/tests/data/velodyne_vlp16.pcap";
  ASSERT_EQ(run({"replay", capture, "--fast", "--profile", "--out", out.string(), "--export-scans",
                 (out / "scans").string()}),
            0);
  const std::string json = slurp(out / "replay.json");
  EXPECT_NE(json.find("\"packets\": 84,"), std::string::npos) << json;
  EXPECT_NE(json.find("\"position_packets\": 16,"), std::string::npos) << json;
  EXPECT_NE(json.find("\"dropped\": 0,"), std::string::npos) << json;
  EXPECT_TRUE(fs::exists(out / "trace.json"));
  EXPECT_TRUE(fs::exists(out / "trace_ingest.json"));
  // The firmware's map and graph tasks ran on the sweeps: both scans went into the map, which
  // then holds a traversable surface (the capture's ground) and a graph on it.
  EXPECT_NE(json.find("\"map\": {\"scans_inserted\": 2,"), std::string::npos) << json;
  EXPECT_EQ(json.find("\"traversable_volume_m3\": 0,"), std::string::npos) << json;
  EXPECT_EQ(json.find("\"graph_nodes\": 0,"), std::string::npos) << json;
  // Every exported point is a line of its scan's CSV; their sum is the decoded point count.
  std::size_t lines = 0, files = 0;
  for (const auto& e : fs::directory_iterator(out / "scans")) {
    std::ifstream f(e.path());
    std::string line;
    std::getline(f, line);
    EXPECT_EQ(line, "x,y,z,intensity,ring,time_offset_ns");
    while (std::getline(f, line)) ++lines;
    ++files;
  }
  EXPECT_GE(files, 1u);
  const auto at = json.find("\"points\": ");
  ASSERT_NE(at, std::string::npos);
  EXPECT_EQ(std::to_string(lines), json.substr(at + 10, json.find(',', at) - at - 10));
}

TEST(Replay, NoMapSkipsTheFirmwareTasks) {
  const fs::path out = fs::temp_directory_path() / "storey_replay_nomap";
  fs::remove_all(out);
  const std::string capture = std::string(STOREY_SOURCE_DIR) + "/tests/data/velodyne_vlp16.pcap";
  ASSERT_EQ(run({"replay", capture, "--fast", "--no-map", "--out", out.string()}), 0);
  EXPECT_EQ(slurp(out / "replay.json").find("\"map\""), std::string::npos);
}

TEST(Replay, BadInputIsAOneLineErrorNotACrash) {
  EXPECT_EQ(run({"replay"}), 2);
  EXPECT_EQ(run({"replay", "/nonexistent/capture.pcap", "--out", "/tmp/storey_replay_bad"}), 2);
  EXPECT_EQ(run({"replay", "x.pcap", "--rate", "-1"}), 2);
  EXPECT_EQ(run({"replay", "x.pcap", "--sensor", "hdl64"}), 2);
  EXPECT_EQ(run({"replay", "x.pcap", "--config", "/nonexistent/storey.yaml"}), 2);
  const fs::path junk = fs::temp_directory_path() / "storey_junk.pcap";
  std::ofstream(junk) << "this is not a capture";
  EXPECT_EQ(run({"replay", junk.string(), "--out", "/tmp/storey_replay_bad"}), 2);
}

}  // namespace
