#include <gtest/gtest.h>

#include "tools/eval/eval_options.hpp"

namespace storey::tools::eval {
namespace {

ParseResult parse(std::vector<std::string> a) {
  return parse_eval_args(a);
}

TEST(EvalOptions, DefaultsAreEveryScenesAndMethodFiveSeeds) {
  const ParseResult r = parse({});
  ASSERT_TRUE(r.ok()) << r.error;
  ASSERT_EQ(r.options.groups.size(), 1u);
  EXPECT_EQ(r.options.groups[0].scenes, default_scenes());
  EXPECT_EQ(r.options.groups[0].methods, default_methods());
  EXPECT_EQ(r.options.groups[0].ablations, std::vector<std::string>{"full"});
  EXPECT_EQ(r.options.seeds, (std::vector<uint64_t>{1, 2, 3, 4, 5}));
  EXPECT_EQ(r.options.out_dir, "out/eval");
  EXPECT_EQ(r.options.jobs, 0);
}

TEST(EvalOptions, ListsSeedsAndValues) {
  const ParseResult r =
      parse({"--scenes", "maze,test_box_room", "--methods", "storey", "--ablations",
             "full,no-c-sur", "--seeds", "3", "--jobs", "4", "--time-limit", "60.5", "--out", "x/y",
             "--storey", "/bin/true", "--config", "c.yaml"});
  ASSERT_TRUE(r.ok()) << r.error;
  const auto& g = r.options.groups.at(0);
  EXPECT_EQ(g.scenes, (std::vector<std::string>{"maze", "test_box_room"}));
  EXPECT_EQ(g.ablations, (std::vector<std::string>{"full", "no-c-sur"}));
  EXPECT_EQ(r.options.seeds, (std::vector<uint64_t>{1, 2, 3}));
  EXPECT_EQ(r.options.jobs, 4);
  // A number replaces every scene's limit, the teaching building's default included.
  EXPECT_DOUBLE_EQ(r.options.time_limits.for_scene("maze"), 60.5);
  EXPECT_DOUBLE_EQ(r.options.time_limits.for_scene("teaching_building"), 60.5);
  EXPECT_EQ(r.options.out_dir, "x/y");
  EXPECT_EQ(r.options.storey, "/bin/true");
  EXPECT_EQ(r.options.config, "c.yaml");
  // A list is exactly those seeds (duplicates once).
  EXPECT_EQ(parse({"--seeds", "7,3,7"}).options.seeds, (std::vector<uint64_t>{7, 3}));
}

TEST(EvalOptions, TimeLimitsPerScene) {
  // Default: 1800 s, the teaching building 3000 s (our robot needs ~2000 s there).
  const TimeLimits d = parse({}).options.time_limits;
  EXPECT_DOUBLE_EQ(d.for_scene("maze"), 1800);
  EXPECT_DOUBLE_EQ(d.for_scene("teaching_building"), 3000);
  // SCENE=S on top of the defaults, in any order with the number.
  const ParseResult r = parse({"--time-limit", "maze=2400,900,office=100.5"});
  ASSERT_TRUE(r.ok()) << r.error;
  const TimeLimits& t = r.options.time_limits;
  EXPECT_DOUBLE_EQ(t.for_scene("maze"), 2400);
  EXPECT_DOUBLE_EQ(t.for_scene("office"), 100.5);
  EXPECT_DOUBLE_EQ(t.for_scene("house"), 900);
  EXPECT_DOUBLE_EQ(t.for_scene("teaching_building"), 900);
  EXPECT_EQ(t.describe(), "900 s, maze 2400 s, office 100.5 s");
  const ParseResult k = parse({"--preset", "paper", "--time-limit", "maze=2400"});
  ASSERT_TRUE(k.ok()) << k.error;
  EXPECT_DOUBLE_EQ(k.options.time_limits.for_scene("teaching_building"), 3000);
  EXPECT_DOUBLE_EQ(k.options.time_limits.for_scene("house"), 1800);
  // The error lists the matrix's scenes once each (the paper preset has maze in two groups).
  EXPECT_EQ(parse({"--preset", "paper", "--time-limit", "mze=5"}).error,
            "--time-limit: scene 'mze' is not in the matrix (scenes: office, maze, "
            "teaching_building, house)");
  // A scene file is named by its stem, as in the run folders.
  EXPECT_TRUE(parse({"--scenes", "x/hall.yaml", "--time-limit", "hall=5"}).ok());
}

TEST(EvalOptions, ErrorsNameTheFlag) {
  struct Case {
    std::vector<std::string> args;
    std::string starts;
  };
  const Case cases[] = {
      {{"--seeds", "0"}, "--seeds 0:"},
      {{"--seeds", "x"}, "--seeds x:"},
      {{"--seeds", "1,b"}, "--seeds 1,b:"},
      {{"--jobs", "0"}, "--jobs 0:"},
      {{"--jobs", "-2"}, "--jobs -2:"},
      {{"--time-limit", "-5"}, "--time-limit -5:"},
      {{"--time-limit", "nan"}, "--time-limit nan:"},
      {{"--time-limit", "600,700"}, "--time-limit 600,700: two limits"},
      {{"--time-limit", "maze="}, "--time-limit maze=:"},
      {{"--time-limit", "a b=5"}, "--time-limit a b=5: bad scene name"},
      {{"--scenes", "maze", "--time-limit", "office=900"}, "--time-limit: scene 'office' is not"},
      {{"--preset", "everything"}, "--preset everything:"},
      {{"--methods", "storey,../../etc"}, "--methods storey,../../etc:"},
      {{"--ablations", "a b"}, "--ablations a b:"},
      {{"--scenes", ""}, "--scenes :"},
      {{"--out"}, "--out: missing value"},
      {{"--out", ""}, "--out:"},
      {{"--frobnicate"}, "unknown argument '--frobnicate'"},
      {{"--preset", "tables", "--methods", "storey"}, "--methods: cannot be combined"},
  };
  for (const auto& c : cases) {
    const ParseResult r = parse(c.args);
    EXPECT_FALSE(r.ok()) << c.args[0];
    EXPECT_EQ(r.error.rfind(c.starts, 0), 0u) << "got: " << r.error;
  }
}

TEST(EvalOptions, PresetsFixThePapersMatrices) {
  const ParseResult t = parse({"--preset", "tables"});
  ASSERT_TRUE(t.ok()) << t.error;
  ASSERT_EQ(t.options.groups.size(), 1u);
  EXPECT_EQ(t.options.groups[0].methods, default_methods());
  EXPECT_EQ(t.options.groups[0].ablations, std::vector<std::string>{"full"});

  const ParseResult a = parse({"--preset", "ablations", "--seeds", "2"});
  ASSERT_TRUE(a.ok()) << a.error;
  ASSERT_EQ(a.options.groups.size(), 1u);
  EXPECT_EQ(a.options.groups[0].scenes, std::vector<std::string>{"maze"});
  EXPECT_EQ(a.options.groups[0].methods, std::vector<std::string>{"storey"});
  EXPECT_EQ(a.options.groups[0].ablations,
            (std::vector<std::string>{"full", "no-tentative", "no-c-sur", "no-c-exp",
                                      "boundary-frontiers", "no-prior", "no-incremental"}));
  EXPECT_EQ(a.options.seeds.size(), 2u);
  EXPECT_EQ(parse({"--preset", "paper"}).options.groups.size(), 2u);
}

TEST(EvalOptions, HelpStopsParsing) {
  EXPECT_TRUE(parse({"--help", "--jobs", "0"}).options.help);
}

}  // namespace
}  // namespace storey::tools::eval
