// How an exhausted run ends (firmware/autonomy.hpp): complete, or stranded when the frontiers
// left are unreachable from a robot cut off in a small part of its graph.
#include <gtest/gtest.h>

#include "firmware/autonomy.hpp"

namespace storey::firmware {
namespace {

ExplorationStatus exhausted(uint32_t nodes, uint32_t robot_part, uint32_t unreachable) {
  ExplorationStatus s;
  s.nodes = nodes;
  s.robot_component_nodes = robot_part;
  s.clusters = unreachable + 2;
  s.clusters_set_aside = 2;
  s.clusters_unreachable = unreachable;
  return s;
}

// teaching_building seed 1, session 31: 293 of 300 clusters unreachable from a 3-node component
// (of 1,580) claimed "complete". A floor climbed blind can be a part of its own (house seed 4,
// session 32: the robot's 184 of 362 nodes): with a cluster unreachable below, still complete.
// Nothing unreachable: complete however small the robot's part.
TEST(Autonomy, AnExhaustedRunCutOffInASmallPartOfItsGraphIsStranded) {
  EXPECT_TRUE(Autonomy::stranded(exhausted(1580, 3, 293)));
  EXPECT_FALSE(Autonomy::stranded(exhausted(362, 184, 1)));
  EXPECT_FALSE(Autonomy::stranded(exhausted(1580, 3, 0)));
  EXPECT_TRUE(Autonomy::stranded(exhausted(1000, 99, 1)));
  EXPECT_FALSE(Autonomy::stranded(exhausted(1000, 100, 1)));
  EXPECT_STREQ(to_string(ExplorationState::kStranded), "stranded");
}

// The progress lines name what the robot heads for: a cluster, a goal toward a zone, or nothing.
TEST(Autonomy, ProgressNamesTheTarget) {
  ExplorationStatus s;
  EXPECT_EQ(describe_target(s), "");
  s.has_target = true;
  s.target_cluster = 12;
  s.target_x_m = 3.04f;
  s.target_y_m = -4.5f;
  s.target_z_m = 3.0f;
  EXPECT_EQ(describe_target(s), "  -> cluster 12 at 3.0, -4.5, 3.0");
  s.target_cluster = -1;
  EXPECT_EQ(describe_target(s), "  -> goal at 3.0, -4.5, 3.0");
}

}  // namespace
}  // namespace storey::firmware
