// SectionReader on its own: each value kind, each error kind, and the typo suggestions.
#include "config/yaml_reader.hpp"

#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

namespace storey::config {
namespace {

std::vector<std::string> messages(const ReadContext& ctx) {
  std::vector<std::string> out;
  for (const ConfigError& e : ctx.errors()) out.push_back(e.to_string());
  return out;
}

struct Fields {
  double d = 1.0;
  float f = 2.0f;
  int i = 3;
  bool b = false;
  std::string s = "x";
  double angle_rad = 0.0;
  std::array<double, 3> xyz{0, 0, 0};
  std::array<double, 2> ab_rad{0, 0};
  enum class Colour { kRed, kGreen } colour = Colour::kRed;
};

constexpr EnumName<Fields::Colour> kColours[] = {{"red", Fields::Colour::kRed},
                                                 {"green", Fields::Colour::kGreen}};

// Reads `text` as the section "sec" of file "f.yaml" and returns the errors.
std::vector<std::string> read(const std::string& text, Fields& out, ReadContext& ctx) {
  YAML::Node root = YAML::Load(text);
  SectionReader top(root, "", std::make_shared<const std::string>("f.yaml"), 0, ctx);
  {
    SectionReader r = top.section("sec");
    r.get("d", out.d, Range{0.0, 10.0});
    r.get("f", out.f, Range{-1.0, 5.0});
    r.get("i", out.i, Range{0, 100});
    r.get("b", out.b);
    r.get("s", out.s);
    r.get_deg("angle_deg", out.angle_rad, Range{-90.0, 90.0});
    r.get_list("xyz_m", out.xyz, Range{-5.0, 5.0});
    r.get_list_deg("ab_deg", out.ab_rad, Range{-180.0, 180.0});
    r.get_enum("colour", out.colour, kColours);
  }
  top.finish();
  return messages(ctx);
}

std::vector<std::string> read(const std::string& text, Fields& out) {
  ReadContext ctx;
  return read(text, out, ctx);
}

TEST(YamlReader, ReadsEveryKindOfValue) {
  Fields f;
  const auto errors = read(
      "sec:\n"
      "  d: 2.5\n"
      "  f: -0.5\n"
      "  i: +42\n"
      "  b: true\n"
      "  s: hello\n"
      "  angle_deg: 45\n"
      "  xyz_m: [1, -2.5, 3e-1]\n"
      "  ab_deg: [90, -180]\n"
      "  colour: green\n",
      f);
  EXPECT_TRUE(errors.empty()) << errors.front();
  EXPECT_DOUBLE_EQ(f.d, 2.5);
  EXPECT_FLOAT_EQ(f.f, -0.5f);
  EXPECT_EQ(f.i, 42);
  EXPECT_TRUE(f.b);
  EXPECT_EQ(f.s, "hello");
  EXPECT_NEAR(f.angle_rad, 0.7853981633974483, 1e-15);
  EXPECT_DOUBLE_EQ(f.xyz[1], -2.5);
  EXPECT_DOUBLE_EQ(f.xyz[2], 0.3);
  EXPECT_NEAR(f.ab_rad[0], 1.5707963267948966, 1e-15);
  EXPECT_NEAR(f.ab_rad[1], -3.141592653589793, 1e-15);
  EXPECT_EQ(f.colour, Fields::Colour::kGreen);
}

TEST(YamlReader, AbsentKeysKeepDefaults) {
  Fields f;
  EXPECT_TRUE(read("sec:\n  d: 4\n", f).empty());
  EXPECT_DOUBLE_EQ(f.d, 4.0);
  EXPECT_EQ(f.i, 3);
  EXPECT_EQ(f.s, "x");
  Fields g;
  EXPECT_TRUE(read("other_than_sec: null\n", g).size() == 1);  // the unknown top-level key
  EXPECT_EQ(g.i, 3);
}

TEST(YamlReader, UnknownKeySuggestsTheNearestKnownOne) {
  Fields f;
  const auto errors = read("sec:\n  d: 1\n  colur: red\n  zzzzzz: 1\n", f);
  ASSERT_EQ(errors.size(), 2u);
  EXPECT_EQ(errors[0], "f.yaml:3: sec.colur: unknown key (did you mean 'colour'?)");
  EXPECT_EQ(errors[1], "f.yaml:4: sec.zzzzzz: unknown key");
}

TEST(YamlReader, WrongTypesAreNamed) {
  Fields f;
  const auto errors = read(
      "sec:\n"
      "  d: fast\n"
      "  f: \"1.5\"\n"
      "  i: 5.5\n"
      "  b: maybe\n"
      "  s: {a: 1}\n"
      "  xyz_m: 3\n"
      "  colour: [red]\n",
      f);
  ASSERT_EQ(errors.size(), 7u);
  EXPECT_EQ(errors[0], "f.yaml:2: sec.d: expected a number, got 'fast'");
  EXPECT_EQ(errors[1], "f.yaml:3: sec.f: expected a number, got the string \"1.5\"");
  EXPECT_EQ(errors[2], "f.yaml:4: sec.i: expected an integer, got 5.5");
  EXPECT_EQ(errors[3], "f.yaml:5: sec.b: expected true or false, got 'maybe'");
  EXPECT_EQ(errors[4], "f.yaml:6: sec.s: expected a string, got a mapping");
  EXPECT_EQ(errors[5], "f.yaml:7: sec.xyz_m: expected a list of 3 numbers, got '3'");
  EXPECT_EQ(errors[6], "f.yaml:8: sec.colour: expected one of red, green, got a list");
  // Failed values leave the defaults in place.
  EXPECT_DOUBLE_EQ(f.d, 1.0);
  EXPECT_EQ(f.i, 3);
}

TEST(YamlReader, OutOfRangeAndNonFiniteNumbers) {
  Fields f;
  const auto errors = read(
      "sec:\n"
      "  d: 10.5\n"
      "  i: -1\n"
      "  f: .nan\n"
      "  angle_deg: 91\n"
      "  xyz_m: [0, 0,\n"
      "          6]\n",
      f);
  ASSERT_EQ(errors.size(), 5u);
  EXPECT_EQ(errors[0], "f.yaml:2: sec.d: 10.5 is out of range [0, 10]");
  EXPECT_EQ(errors[1], "f.yaml:4: sec.f: must be a finite number, got .nan");
  EXPECT_EQ(errors[2], "f.yaml:3: sec.i: -1 is out of range [0, 100]");
  EXPECT_EQ(errors[3], "f.yaml:5: sec.angle_deg: 91 is out of range [-90, 90]");
  EXPECT_EQ(errors[4], "f.yaml:7: sec.xyz_m[2]: 6 is out of range [-5, 5]");
}

TEST(YamlReader, ListLengthAndBadEnum) {
  Fields f;
  const auto errors = read("sec:\n  xyz_m: [1, 2]\n  colour: gren\n  ab_deg: [1, 2, 3]\n", f);
  ASSERT_EQ(errors.size(), 3u);
  EXPECT_EQ(errors[0], "f.yaml:2: sec.xyz_m: expected a list of 3 numbers, got 2 elements");
  EXPECT_EQ(errors[1], "f.yaml:4: sec.ab_deg: expected a list of 2 numbers, got 3 elements");
  EXPECT_EQ(errors[2],
            "f.yaml:3: sec.colour: 'gren' is not one of red, green (did you mean 'green'?)");
}

TEST(YamlReader, MissingValueAndDuplicateKey) {
  Fields f;
  const auto errors = read("sec:\n  d:\n  i: 1\n  i: 2\n", f);
  ASSERT_EQ(errors.size(), 2u);
  EXPECT_EQ(errors[0], "f.yaml:2: sec.d: missing value");
  EXPECT_EQ(errors[1], "f.yaml:4: sec.i: duplicate key (first given on line 3)");
}

TEST(YamlReader, SectionThatIsNotAMapping) {
  Fields f;
  const auto errors = read("sec: 5\n", f);
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_EQ(errors[0], "f.yaml:1: sec: expected a mapping, got '5'");
}

TEST(YamlReader, RequiredKeysAreCheckedAcrossLayers) {
  ReadContext ctx;
  auto file = std::make_shared<const std::string>("a.yaml");
  int v = 0;
  {
    YAML::Node n = YAML::Load("x: 1\n");
    SectionReader r(n, "", file, 0, ctx);
    r.get("need", v, Range{0, 9}, Need::kRequired);
    r.known("x");
  }
  ctx.check_required();
  ASSERT_EQ(ctx.errors().size(), 1u);
  EXPECT_EQ(ctx.errors()[0].to_string(), "a.yaml: need: missing required value");

  // Given in a later layer: satisfied.
  ReadContext ctx2;
  for (const char* text : {"{}", "need: 4\n"}) {
    YAML::Node n = YAML::Load(text);
    SectionReader r(n, "", file, 0, ctx2);
    r.get("need", v, Range{0, 9}, Need::kRequired);
  }
  ctx2.check_required();
  EXPECT_TRUE(ctx2.errors().empty());
  EXPECT_EQ(v, 4);
  EXPECT_EQ(ctx2.origin("need", Location{}).line, 1);
}

TEST(YamlReader, StringCheckRejectsWithReason) {
  ReadContext ctx;
  YAML::Node n = YAML::Load("name: bad name\n");
  std::string s = "keep";
  {
    SectionReader r(n, "top", std::make_shared<const std::string>("c.yaml"), 0, ctx);
    r.get("name", s, [](const std::string& v) -> std::string {
      return v.find(' ') == std::string::npos ? "" : "no spaces allowed";
    });
  }
  ASSERT_EQ(ctx.errors().size(), 1u);
  EXPECT_EQ(ctx.errors()[0].to_string(), "c.yaml:1: top.name: no spaces allowed");
  EXPECT_EQ(s, "keep");
}

TEST(EditDistance, CountsSwapsAsOneEdit) {
  EXPECT_EQ(edit_distance("voxel_size_m", "voxel_size_m"), 0u);
  EXPECT_EQ(edit_distance("voxle_size_m", "voxel_size_m"), 1u);
  EXPECT_EQ(edit_distance("voxel_size", "voxel_size_m"), 2u);
  EXPECT_EQ(edit_distance("", "abc"), 3u);
  EXPECT_EQ(edit_distance("kitten", "sitting"), 3u);
}

TEST(EditDistance, SuggestsOnlyPlausibleTypos) {
  const std::set<std::string, std::less<>> keys{"r_e_m", "rho_min", "probes", "theta_min"};
  EXPECT_EQ(closest_match("theta_mni", keys), "theta_min");
  EXPECT_EQ(closest_match("probe", keys), "probes");
  EXPECT_EQ(closest_match("colour", keys), "");
  EXPECT_EQ(closest_match("x", keys), "");
}

}  // namespace
}  // namespace storey::config
