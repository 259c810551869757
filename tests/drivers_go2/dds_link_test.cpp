// The Go2 DDS interface: IDL type names and layouts against the published unitree_sdk2
// definitions, Move's JSON parameter, and a round trip with the stand-in over loopback.
#include "drivers/go2/dds_link.hpp"

#include <gtest/gtest.h>
#include <stddef.h>

#include <cstring>
#include <string>

#include "drivers/go2/dds_go2_types.hpp"
#include "drivers/go2/robot_standin.hpp"
#include "drivers/go2/sport_api.hpp"
#include "test_helpers.hpp"

namespace storey::drivers::go2 {
namespace {

using testing::mono_ns;
using testing::spin_until;

// Type names are what DDS matches on: they must be exactly the robot's.
TEST(Go2Idl, TypeNamesMatchUnitreeSdk2) {
  EXPECT_STREQ(unitree_go_msg_dds__SportModeState__desc.m_typename,
               "unitree_go::msg::dds_::SportModeState_");
  EXPECT_STREQ(unitree_go_msg_dds__LowState__desc.m_typename, "unitree_go::msg::dds_::LowState_");
  EXPECT_STREQ(unitree_go_msg_dds__IMUState__desc.m_typename, "unitree_go::msg::dds_::IMUState_");
  EXPECT_STREQ(unitree_go_msg_dds__MotorState__desc.m_typename,
               "unitree_go::msg::dds_::MotorState_");
  EXPECT_STREQ(unitree_go_msg_dds__BmsState__desc.m_typename, "unitree_go::msg::dds_::BmsState_");
  EXPECT_STREQ(unitree_go_msg_dds__TimeSpec__desc.m_typename, "unitree_go::msg::dds_::TimeSpec_");
  EXPECT_STREQ(unitree_go_msg_dds__PathPoint__desc.m_typename, "unitree_go::msg::dds_::PathPoint_");
  EXPECT_STREQ(unitree_api_msg_dds__Request__desc.m_typename, "unitree_api::msg::dds_::Request_");
  EXPECT_STREQ(unitree_api_msg_dds__RequestHeader__desc.m_typename,
               "unitree_api::msg::dds_::RequestHeader_");
  EXPECT_STREQ(unitree_api_msg_dds__RequestIdentity__desc.m_typename,
               "unitree_api::msg::dds_::RequestIdentity_");
  EXPECT_STREQ(unitree_api_msg_dds__RequestLease__desc.m_typename,
               "unitree_api::msg::dds_::RequestLease_");
  EXPECT_STREQ(unitree_api_msg_dds__RequestPolicy__desc.m_typename,
               "unitree_api::msg::dds_::RequestPolicy_");
  EXPECT_STREQ(unitree_api_msg_dds__Response__desc.m_typename, "unitree_api::msg::dds_::Response_");
}

// Field order and sizes from the published field lists (PROTOCOLS.md "Unitree Go2 (DDS)";
// unitree_sdk2 include/unitree/idl/go2/*.hpp, unitree_sdk2_python idl/unitree_go/msg/dds_).
// C struct offsets with natural alignment follow from the IDL order, so a reordered or retyped
// field shows up here.
TEST(Go2Idl, StructLayoutsMatchPublishedFieldLists) {
  using S = unitree_go_msg_dds__SportModeState_;
  EXPECT_EQ(sizeof(unitree_go_msg_dds__TimeSpec_), 8u);
  EXPECT_EQ(sizeof(unitree_go_msg_dds__IMUState_), 56u);  // 13 floats + u8 + pad
  EXPECT_EQ(sizeof(unitree_go_msg_dds__PathPoint_), 28u);
  EXPECT_EQ(offsetof(S, stamp), 0u);
  EXPECT_EQ(offsetof(S, error_code), 8u);
  EXPECT_EQ(offsetof(S, imu_state), 12u);
  EXPECT_EQ(offsetof(S, mode), 68u);
  EXPECT_EQ(offsetof(S, progress), 72u);
  EXPECT_EQ(offsetof(S, gait_type), 76u);
  EXPECT_EQ(offsetof(S, foot_raise_height), 80u);
  EXPECT_EQ(offsetof(S, position), 84u);
  EXPECT_EQ(offsetof(S, body_height), 96u);
  EXPECT_EQ(offsetof(S, velocity), 100u);
  EXPECT_EQ(offsetof(S, yaw_speed), 112u);
  EXPECT_EQ(offsetof(S, range_obstacle), 116u);
  EXPECT_EQ(offsetof(S, foot_force), 132u);
  EXPECT_EQ(offsetof(S, foot_position_body), 140u);
  EXPECT_EQ(offsetof(S, foot_speed_body), 188u);
  EXPECT_EQ(offsetof(S, path_point), 236u);
  EXPECT_EQ(sizeof(S), 236u + 10 * 28u);

  // MotorState_: u8 mode, 7 f32, u8 temperature, u32 lost, u32 reserve[2].
  EXPECT_EQ(offsetof(unitree_go_msg_dds__MotorState_, q), 4u);
  EXPECT_EQ(offsetof(unitree_go_msg_dds__MotorState_, temperature), 32u);
  EXPECT_EQ(offsetof(unitree_go_msg_dds__MotorState_, lost), 36u);
  EXPECT_EQ(sizeof(unitree_go_msg_dds__MotorState_), 48u);
  // BmsState_: 4 x u8, i32 current, u16 cycle, u8 bq_ntc[2], u8 mcu_ntc[2], u16 cell_vol[15].
  EXPECT_EQ(offsetof(unitree_go_msg_dds__BmsState_, current), 4u);
  EXPECT_EQ(offsetof(unitree_go_msg_dds__BmsState_, cell_vol), 14u);
  EXPECT_EQ(sizeof(unitree_go_msg_dds__BmsState_), 44u);
  using L = unitree_go_msg_dds__LowState_;
  EXPECT_EQ(offsetof(L, head), 0u);
  EXPECT_EQ(offsetof(L, level_flag), 2u);
  EXPECT_EQ(offsetof(L, frame_reserve), 3u);
  EXPECT_EQ(offsetof(L, sn), 4u);
  EXPECT_EQ(offsetof(L, version), 12u);
  EXPECT_EQ(offsetof(L, bandwidth), 20u);
  EXPECT_EQ(offsetof(L, imu_state), 24u);
  EXPECT_EQ(offsetof(L, motor_state), 80u);
  EXPECT_EQ(offsetof(L, bms_state), 80u + 20 * 48u);
  EXPECT_EQ(offsetof(L, foot_force), 1084u);
  EXPECT_EQ(offsetof(L, foot_force_est), 1092u);
  EXPECT_EQ(offsetof(L, tick), 1100u);
  EXPECT_EQ(offsetof(L, wireless_remote), 1104u);
  EXPECT_EQ(offsetof(L, bit_flag), 1144u);
  EXPECT_EQ(offsetof(L, adc_reel), 1148u);
  EXPECT_EQ(offsetof(L, temperature_ntc1), 1152u);
  EXPECT_EQ(offsetof(L, temperature_ntc2), 1153u);
  EXPECT_EQ(offsetof(L, power_v), 1156u);
  EXPECT_EQ(offsetof(L, power_a), 1160u);
  EXPECT_EQ(offsetof(L, fan_frequency), 1164u);
  EXPECT_EQ(offsetof(L, reserve), 1172u);
  EXPECT_EQ(offsetof(L, crc), 1176u);
  EXPECT_EQ(sizeof(L), 1180u);

  using R = unitree_api_msg_dds__Request_;
  EXPECT_EQ(sizeof(unitree_api_msg_dds__RequestIdentity_), 16u);
  EXPECT_EQ(sizeof(unitree_api_msg_dds__RequestLease_), 8u);
  EXPECT_EQ(sizeof(unitree_api_msg_dds__RequestPolicy_), 8u);
  EXPECT_EQ(offsetof(unitree_api_msg_dds__RequestHeader_, identity), 0u);
  EXPECT_EQ(offsetof(unitree_api_msg_dds__RequestHeader_, lease), 16u);
  EXPECT_EQ(offsetof(unitree_api_msg_dds__RequestHeader_, policy), 24u);
  EXPECT_EQ(offsetof(R, header), 0u);
  EXPECT_EQ(offsetof(R, parameter), 32u);
  EXPECT_EQ(offsetof(R, binary), 40u);
  // Fixed-size state types are what lets DdsLink take() without allocating.
  EXPECT_TRUE(unitree_go_msg_dds__SportModeState__desc.m_flagset & DDS_TOPIC_FIXED_SIZE);
  EXPECT_TRUE(unitree_go_msg_dds__LowState__desc.m_flagset & DDS_TOPIC_FIXED_SIZE);
}

TEST(SportApi, MoveParameterFormatsAndParses) {
  char buf[96];
  const size_t n = format_move_parameter(0.3f, -0.1f, 0.5f, buf, sizeof(buf));
  ASSERT_GT(n, 0u);
  EXPECT_STREQ(buf, "{\"x\": 0.3, \"y\": -0.1, \"z\": 0.5}");
  float x, y, z;
  ASSERT_TRUE(parse_move_parameter(buf, n, x, y, z));
  EXPECT_EQ(x, 0.3f);
  EXPECT_EQ(y, -0.1f);
  EXPECT_EQ(z, 0.5f);
  // Python sport_client's json.dumps output and reordered keys parse too.
  const std::string py = "{\"x\": 0.0, \"y\": 0.25, \"z\": -1.0}";
  ASSERT_TRUE(parse_move_parameter(py.data(), py.size(), x, y, z));
  EXPECT_EQ(y, 0.25f);
  const std::string re = " { \"z\":1 ,\"x\":2,\"y\":3 } ";
  ASSERT_TRUE(parse_move_parameter(re.data(), re.size(), x, y, z));
  EXPECT_EQ(x, 2.0f);
  for (const char* bad : {"", "{", "{\"x\": 1, \"y\": 2}", "{\"x\": nan, \"y\": 0, \"z\": 0}",
                          "{\"x\": 1e999, \"y\": 0, \"z\": 0}", "{\"x\" 1, \"y\": 0, \"z\": 0}",
                          "[1,2,3]", "{\"x\": \"1\", \"y\": 0, \"z\": 0}"}) {
    EXPECT_FALSE(parse_move_parameter(bad, std::strlen(bad), x, y, z)) << bad;
  }
  EXPECT_EQ(format_move_parameter(0.3f, 0.1f, 0.5f, buf, 10), 0u);
}

TEST(SportApi, ModeApiIds) {
  EXPECT_EQ(api_id_for(ModeRequest::damp), 1001);
  EXPECT_EQ(api_id_for(ModeRequest::balance_stand), 1002);
  EXPECT_EQ(api_id_for(ModeRequest::stop), 1003);
  EXPECT_EQ(api_id_for(ModeRequest::stand_up), 1004);
  EXPECT_EQ(api_id_for(ModeRequest::stand_down), 1005);
  ModeRequest m;
  EXPECT_FALSE(mode_for_api_id(kApiMove, m));
}

TEST(DdsConfig, LoopbackXmlHasInterfaceUnicastPeers) {
  const std::string x = dds_config_xml(dds_loopback(7));
  EXPECT_NE(x.find("<NetworkInterface name=\"lo\"/>"), std::string::npos);
  EXPECT_NE(x.find("<AllowMulticast>false</AllowMulticast>"), std::string::npos);
  EXPECT_NE(x.find("<Peer address=\"127.0.0.1\"/>"), std::string::npos);
  EXPECT_NE(x.find("<ParticipantIndex>auto</ParticipantIndex>"), std::string::npos);
  const std::string r = dds_config_xml(dds_robot_network("eth0"));
  EXPECT_NE(r.find("<NetworkInterface name=\"eth0\"/>"), std::string::npos);
  EXPECT_EQ(r.find("<Peers>"), std::string::npos);
}

// Stand-in and link in one process share the domain instance (CycloneDDS allows one per id per
// process); the cross-process test below goes through the loopback interface.
TEST(DdsLink, RoundTripWithStandinInProcess) {
  const DdsNetworkOptions net = dds_loopback(41);
  StandinOptions so;
  so.transport = StandinTransport::dds;
  so.dds = net;
  so.state_period_ns = 0;
  const int64_t t0 = mono_ns();
  RobotStandin robot(so, t0);
  ASSERT_TRUE(robot.ok()) << robot.error();
  DdsLinkOptions lo;
  lo.network = net;
  DdsLink link(lo, t0);
  ASSERT_TRUE(link.ok()) << link.error();

  RobotState given;
  given.position = {1.25f, 2.5f, 0.3f};
  given.velocity = {0.4f, 0.0f, 0.0f};
  given.yaw_speed = 0.2f;
  given.mode = 3;
  given.gait = 1;
  given.foot_force = {11, 22, 33, 44};
  given.battery_voltage = 27.5f;
  given.battery_current = 2.0f;
  given.battery_soc = 64;
  robot.set_state(given);
  ASSERT_TRUE(spin_until(
      [&] {
        robot.step(mono_ns());
        link.poll(mono_ns());
      },
      [&] { return link.has_state() && link.latest_state().battery_soc == 64; }))
      << "no state over DDS";
  const RobotState& s = link.latest_state();
  EXPECT_EQ(s.position, given.position);
  EXPECT_EQ(s.velocity, given.velocity);
  EXPECT_EQ(s.yaw_speed, 0.2f);
  EXPECT_EQ(s.mode, 3);
  EXPECT_EQ(s.gait, 1);
  EXPECT_EQ(s.foot_force, given.foot_force);
  EXPECT_EQ(s.battery_voltage, 27.5f);

  ASSERT_TRUE(spin_until([] {}, [&] { return link.matched_request_readers() > 0; }));
  const int64_t t = mono_ns();
  ASSERT_EQ(link.send_velocity(VelocityCommand{t, 0.3f, -0.1f, 0.5f}, t), LinkStatus::ok);
  ASSERT_TRUE(
      spin_until([&] { robot.step(mono_ns()); }, [&] { return robot.velocity_commands() == 1; }));
  EXPECT_EQ(robot.last_velocity().velocity.vx, 0.3f);
  EXPECT_EQ(robot.last_velocity().velocity.vy, -0.1f);
  EXPECT_EQ(robot.last_velocity().velocity.yaw_rate, 0.5f);
  EXPECT_EQ(robot.last_velocity().velocity.stamp_ns, t);  // request identity id = send time

  ASSERT_EQ(link.send_mode(ModeCommand{mono_ns(), ModeRequest::stop}, mono_ns()), LinkStatus::ok);
  ASSERT_TRUE(
      spin_until([&] { robot.step(mono_ns()); }, [&] { return robot.mode_commands() == 1; }));
  EXPECT_EQ(robot.last_mode().mode.mode, ModeRequest::stop);
  // Stale command refused before it reaches DDS.
  EXPECT_EQ(link.send_velocity(VelocityCommand{t - 1'000'000'000, 1, 0, 0}, t),
            LinkStatus::stale_command);
  const LinkHealth h = link.health(mono_ns());
  EXPECT_EQ(h.commands_sent, 2u);
  EXPECT_EQ(h.stale_commands_refused, 1u);
  EXPECT_EQ(h.commands_rejected, 0u);
}

TEST(DdsLink, LinkLostWithoutPublisherAtInjectedTime) {
  DdsLinkOptions lo;
  lo.network = dds_loopback(42);
  lo.link.state_timeout_ns = 100'000'000;
  const int64_t t0 = mono_ns();
  DdsLink link(lo, t0);
  ASSERT_TRUE(link.ok()) << link.error();
  link.poll(t0 + 100'000'000);
  EXPECT_FALSE(link.health(t0 + 100'000'000).link_lost);
  link.poll(t0 + 120'000'000);
  EXPECT_TRUE(link.health(t0 + 120'000'000).link_lost);
  EXPECT_EQ(link.health(t0 + 120'000'000).link_lost_events, 1u);
}

}  // namespace
}  // namespace storey::drivers::go2
