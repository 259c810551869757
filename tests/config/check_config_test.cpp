// The `storey check-config` verb, called directly (exit codes and what it prints).
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "firmware/commands.hpp"

namespace storey::firmware {
namespace {

struct Outcome {
  int code;
  std::string out;
  std::string err;
};

Outcome run(std::vector<std::string> args) {
  args.insert(args.begin(), "check-config");
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  testing::internal::CaptureStdout();
  testing::internal::CaptureStderr();
  const int code = cmd_check_config(static_cast<int>(args.size()), argv.data());
  Outcome r{code, testing::internal::GetCapturedStdout(), testing::internal::GetCapturedStderr()};
  return r;
}

const std::string kConfigDir = std::string(STOREY_SOURCE_DIR) + "/config/";

TEST(CheckConfig, ShippedFilesAreOk) {
  for (const char* name : {"default.yaml", "go2_mid360.yaml", "hil.yaml"}) {
    const std::string path = kConfigDir + name;
    const Outcome r = run({path});
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(r.out.rfind(path + ": ok\n", 0), 0u) << r.out;
    EXPECT_NE(r.out.find("control"), std::string::npos) << r.out;
    EXPECT_TRUE(r.err.empty()) << r.err;
  }
  const Outcome r = run({kConfigDir + "go2_mid360.yaml"});
  EXPECT_NE(r.out.find("mid360"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("sched_fifo on"), std::string::npos) << r.out;
}

TEST(CheckConfig, TypoPrintsFileKeyLineAndExits2) {
  const std::string f = std::filesystem::temp_directory_path() /
                        ("storey_check_config_" + std::to_string(::getpid()) + ".yaml");
  std::ofstream(f) << "sensor:\n  type: vlp16\n  data_prot: 2368\nlink:\n  transport: sim\n"
                      "map:\n  tau_c: -1\n";
  const Outcome r = run({f});
  std::filesystem::remove(f);
  EXPECT_EQ(r.code, 2);
  EXPECT_TRUE(r.out.empty()) << r.out;
  EXPECT_NE(r.err.find(f + ":3: sensor.data_prot: unknown key (did you mean 'data_port'?)\n"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find(f + ":7: map.tau_c: -1 is out of range [0, 100]\n"), std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find(f + ": 2 errors\n"), std::string::npos) << r.err;
}

TEST(CheckConfig, MissingFileExits2) {
  const Outcome r = run({"/nonexistent/storey.yaml"});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("/nonexistent/storey.yaml: cannot read file"), std::string::npos) << r.err;
}

TEST(CheckConfig, UsageErrorsAndHelp) {
  EXPECT_EQ(run({}).code, 2);
  EXPECT_EQ(run({"a.yaml", "b.yaml"}).code, 2);
  const Outcome bad = run({"--frobnicate"});
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.err.find("unknown option '--frobnicate'"), std::string::npos) << bad.err;
  const Outcome help = run({"--help"});
  EXPECT_EQ(help.code, 0);
  EXPECT_NE(help.out.find("usage: storey check-config FILE"), std::string::npos) << help.out;
}

}  // namespace
}  // namespace storey::firmware
