// DDS over the loopback interface between two processes (CycloneDDS allows one domain instance
// per process, so only separate processes exercise the lo configuration: unicast discovery to
// 127.0.0.1, no multicast). The parent re-executes this test binary as the robot stand-in.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <string>

#include "drivers/go2/dds_link.hpp"
#include "drivers/go2/robot_standin.hpp"
#include "test_helpers.hpp"

namespace storey::drivers::go2 {
namespace {

using testing::mono_ns;
using testing::spin_until;
constexpr const char* kChildEnv = "STOREY_GO2_DDS_CHILD_DOMAIN";

// The child: an integrating stand-in serving DDS on lo until it receives StopMove (or 20 s).
TEST(DdsLoopbackChild, StandinProcess) {
  const char* domain = std::getenv(kChildEnv);
  if (domain == nullptr) {
    GTEST_SKIP()
        << "runs only as the child process of DdsLink.RoundTripAcrossProcessesOverLoopback";
  }
  StandinOptions so;
  so.transport = StandinTransport::dds;
  so.dds = dds_loopback(static_cast<uint32_t>(std::atoi(domain)));
  so.state_period_ns = 5'000'000;
  RobotStandin robot(so, mono_ns());
  ASSERT_TRUE(robot.ok()) << robot.error();
  spin_until([&] { robot.step(mono_ns()); }, [&] { return robot.mode_commands() > 0; }, 20000);
  // Keep publishing briefly so the parent can read the stopped state.
  for (int i = 0; i < 200; ++i) {
    robot.step(mono_ns());
    usleep(1000);
  }
}

TEST(DdsLink, RoundTripAcrossProcessesOverLoopback) {
  const uint32_t domain = 100 + static_cast<uint32_t>(getpid() % 100);
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    setenv(kChildEnv, std::to_string(domain).c_str(), 1);
    execl("/proc/self/exe", "test_drivers_go2", "--gtest_filter=DdsLoopbackChild.StandinProcess",
          static_cast<char*>(nullptr));
    _exit(127);
  }
  DdsLinkOptions lo;
  lo.network = dds_loopback(domain);
  DdsLink link(lo, mono_ns());
  ASSERT_TRUE(link.ok()) << link.error();
  const bool got_state =
      spin_until([&] { link.poll(mono_ns()); }, [&] { return link.has_state(); }, 15000);
  const bool matched =
      got_state && spin_until([] {}, [&] { return link.matched_request_readers() > 0; }, 5000);
  if (got_state && matched) {
    EXPECT_EQ(link.latest_state().mode, static_cast<uint8_t>(RobotModeId::balance_stand));
    // Move with zero yaw rate: the integrating stand-in reports the commanded body velocity
    // unchanged as its odometry-frame velocity (yaw stays 0), so the values can be compared.
    bool moved = spin_until(
        [&] {
          const int64_t t = mono_ns();
          link.send_velocity(VelocityCommand{t, 0.3f, -0.1f, 0.0f}, t);
          link.poll(t);
        },
        [&] {
          const RobotState& s = link.latest_state();
          return s.velocity[0] == 0.3f && s.velocity[1] == -0.1f;
        },
        5000);
    EXPECT_TRUE(moved) << "Move request did not arrive with the right values";
    EXPECT_EQ(link.latest_state().mode, static_cast<uint8_t>(RobotModeId::locomotion));
    EXPECT_EQ(link.send_mode(ModeCommand{mono_ns(), ModeRequest::stop}, mono_ns()), LinkStatus::ok);
  }
  int status = 0;
  bool exited = false;
  for (int i = 0; i < 25000 && !exited; ++i) {
    if (waitpid(child, &status, WNOHANG) == child)
      exited = true;
    else
      usleep(1000);
  }
  if (!exited) {
    kill(child, SIGKILL);
    waitpid(child, &status, 0);
  }
  ASSERT_TRUE(got_state) << "no rt/sportmodestate from the child over lo (domain " << domain
                         << ", config: " << dds_config_xml(lo.network) << ")";
  ASSERT_TRUE(matched) << "request writer never matched the child's reader";
  EXPECT_TRUE(exited && WIFEXITED(status) && WEXITSTATUS(status) == 0)
      << "stand-in child did not finish cleanly after StopMove";
}

}  // namespace
}  // namespace storey::drivers::go2
