#include <gtest/gtest.h>

#include "tools/eval/eval_options.hpp"
#include "tools/eval/run_matrix.hpp"

namespace storey::tools::eval {
namespace {

TEST(RunMatrix, ExpandsScenesMethodsAblationsSeedsInOrder) {
  const auto runs = expand_matrix(
      {{{"office", "maze"}, {"storey", "tare-like"}, {"full", "no-c-sur"}}}, {1, 2, 3});
  ASSERT_EQ(runs.size(), 2u * 2u * 2u * 3u);
  EXPECT_EQ(runs[0], (RunSpec{"office", "storey", "", 1}));
  EXPECT_EQ(runs[2], (RunSpec{"office", "storey", "", 3}));
  EXPECT_EQ(runs[3], (RunSpec{"office", "storey", "no-c-sur", 1}));
  EXPECT_EQ(runs[6], (RunSpec{"office", "tare-like", "", 1}));
  EXPECT_EQ(runs[12].scene, "maze");
}

TEST(RunMatrix, RunsSharedByTwoGroupsAppearOnce) {
  // --preset paper: maze/storey/full is in Tables I and III.
  const ParseResult p = parse_eval_args({"--preset", "paper", "--seeds", "2"});
  ASSERT_TRUE(p.ok());
  const auto runs = expand_matrix(p.options.groups, p.options.seeds);
  EXPECT_EQ(runs.size(), (4u * 4u + 7u - 1u) * 2u);
  size_t maze_storey_full = 0;
  for (const auto& r : runs)
    maze_storey_full += r.scene == "maze" && r.method == "storey" && r.ablation.empty();
  EXPECT_EQ(maze_storey_full, 2u);
}

TEST(RunMatrix, FoldersAndChildArguments) {
  const RunSpec full{"office", "storey", "", 4};
  EXPECT_EQ(full.rel_dir(), "runs/office/storey/seed4");
  EXPECT_EQ(full.sim_args(60, "o/d", ""),
            (std::vector<std::string>{"sim", "--scene", "office", "--method", "storey", "--seed",
                                      "4", "--time-limit", "60", "--out", "o/d"}));
  const RunSpec abl{"/tmp/scenes/my_hall.yaml", "storey", "no-prior", 1};
  EXPECT_EQ(abl.rel_dir(), "runs/my_hall/storey-no-prior/seed1");
  EXPECT_EQ(
      abl.sim_args(1200.5, "d", "c.yaml"),
      (std::vector<std::string>{"sim", "--scene", "/tmp/scenes/my_hall.yaml", "--method", "storey",
                                "--ablation", "no-prior", "--seed", "1", "--time-limit", "1200.5",
                                "--out", "d", "--config", "c.yaml"}));
}

}  // namespace
}  // namespace storey::tools::eval
