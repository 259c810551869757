#include "drivers/go2/link_monitor.hpp"

#include <gtest/gtest.h>

namespace storey::drivers::go2 {
namespace {

constexpr int64_t kMs = 1'000'000;

TEST(LinkMonitor, LinkLostExactlyAfterTimeoutWithInjectedTimes) {
  LinkOptions o;
  o.state_timeout_ns = 100 * kMs;
  LinkMonitor m(o, 0);
  EXPECT_FALSE(m.update(50 * kMs).link_lost);  // grace period at start-up
  EXPECT_TRUE(m.update(100 * kMs + 1).link_lost) << "no state ever: lost after the timeout";
  EXPECT_EQ(m.update(100 * kMs + 2).link_lost_events, 1u);

  m.on_state(200 * kMs);
  LinkHealth h = m.update(200 * kMs);
  EXPECT_FALSE(h.link_lost);
  EXPECT_EQ(h.reconnects, 1u);
  EXPECT_EQ(h.last_state_age_ns, 0);
  // Control task at 50 Hz: the first period after the timeout sees the loss.
  EXPECT_FALSE(m.update(300 * kMs).link_lost);
  EXPECT_TRUE(m.update(300 * kMs + 1).link_lost);
  h = m.update(320 * kMs);
  EXPECT_TRUE(h.link_lost);
  EXPECT_EQ(h.link_lost_events, 2u);
  EXPECT_EQ(h.last_state_age_ns, 120 * kMs);
}

TEST(LinkMonitor, SequenceGapsOutOfOrderWrapAndRestart) {
  LinkMonitor m(LinkOptions{}, 0);
  using S = LinkMonitor::Stream;
  EXPECT_TRUE(m.accept_sequence(S::state, 10));
  EXPECT_TRUE(m.accept_sequence(S::state, 11));
  EXPECT_TRUE(m.accept_sequence(S::state, 15));  // 12, 13, 14 missing
  EXPECT_EQ(m.counters().sequence_gaps, 3u);
  EXPECT_FALSE(m.accept_sequence(S::state, 13));  // late: dropped
  EXPECT_EQ(m.counters().out_of_order, 1u);
  EXPECT_FALSE(m.accept_sequence(S::state, 15));  // duplicate: dropped
  // Heartbeat stream is independent.
  EXPECT_TRUE(m.accept_sequence(S::heartbeat, 0));
  EXPECT_EQ(m.counters().sequence_gaps, 3u);
  // Wrap-around is not a gap.
  LinkMonitor w(LinkOptions{}, 0);
  EXPECT_TRUE(w.accept_sequence(S::state, 0xFFFFFFFFu));
  EXPECT_TRUE(w.accept_sequence(S::state, 0));
  EXPECT_EQ(w.counters().sequence_gaps, 0u);
  // Peer restart (sequence back to 0 from far ahead) resyncs.
  LinkMonitor r(LinkOptions{}, 0);
  EXPECT_TRUE(r.accept_sequence(S::state, 50000));
  EXPECT_TRUE(r.accept_sequence(S::state, 0));
  EXPECT_TRUE(r.accept_sequence(S::state, 1));
  EXPECT_EQ(r.counters().sequence_gaps, 0u);
}

TEST(LinkMonitor, StaleAndInvalidCommandsRefusedAndCounted) {
  LinkOptions o;
  o.max_command_age_ns = 40 * kMs;
  LinkMonitor m(o, 0);
  EXPECT_EQ(m.check_command(100 * kMs, 140 * kMs, true), LinkStatus::ok);
  EXPECT_EQ(m.check_command(100 * kMs, 140 * kMs + 1, true), LinkStatus::stale_command);
  EXPECT_EQ(m.check_command(100 * kMs, 100 * kMs, false), LinkStatus::invalid_command);
  EXPECT_EQ(m.counters().stale_commands_refused, 1u);
  EXPECT_EQ(m.counters().invalid_commands_refused, 1u);
}

}  // namespace
}  // namespace storey::drivers::go2
