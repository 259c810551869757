#include "drivers/go2/link_monitor.hpp"

namespace storey::drivers::go2 {

const char* to_string(LinkStatus s) {
  switch (s) {
    case LinkStatus::ok:
      return "ok";
    case LinkStatus::stale_command:
      return "stale command refused";
    case LinkStatus::invalid_command:
      return "invalid command refused";
    case LinkStatus::would_block:
      return "send would block";
    case LinkStatus::send_failed:
      return "send failed";
    case LinkStatus::not_open:
      return "link not open";
  }
  return "unknown";
}

LinkMonitor::LinkMonitor(const LinkOptions& options, int64_t start_ns)
    : options_(options), start_ns_(start_ns) {
  health_.link_lost = false;  // grace period: lost only once the timeout passes with no state
}

bool LinkMonitor::accept_sequence(Stream stream, uint32_t seq) {
  const int s = static_cast<int>(stream);
  if (!have_seq_[s]) {
    have_seq_[s] = true;
    next_seq_[s] = seq + 1;
    return true;
  }
  // Serial-number arithmetic (RFC 1982 style) so that wrap-around at 2^32 is not a gap.
  const uint32_t ahead = seq - next_seq_[s];
  if (ahead < 0x80000000u) {
    health_.sequence_gaps += ahead;
    next_seq_[s] = seq + 1;
    return true;
  }
  const uint32_t behind = next_seq_[s] - seq;  // >= 1
  if (behind > kRestartWindow) {
    next_seq_[s] = seq + 1;  // the peer restarted: resync without counting a gap
    return true;
  }
  ++health_.out_of_order;
  return false;
}

void LinkMonitor::on_state(int64_t rx_ns) {
  have_state_ = true;
  last_state_rx_ns_ = rx_ns;
  ++health_.states_received;
}

void LinkMonitor::on_heartbeat(int64_t rx_ns) {
  have_heartbeat_ = true;
  last_heartbeat_rx_ns_ = rx_ns;
  ++health_.heartbeats_received;
}

LinkStatus LinkMonitor::check_command(int64_t stamp_ns, int64_t now_ns, bool finite) {
  if (!finite) {
    ++health_.invalid_commands_refused;
    return LinkStatus::invalid_command;
  }
  if (now_ns - stamp_ns > options_.max_command_age_ns) {
    ++health_.stale_commands_refused;
    return LinkStatus::stale_command;
  }
  return LinkStatus::ok;
}

LinkHealth LinkMonitor::update(int64_t now_ns) {
  const int64_t ref = have_state_ ? last_state_rx_ns_ : start_ns_;
  const bool lost = now_ns - ref > options_.state_timeout_ns;
  if (lost && !health_.link_lost) ++health_.link_lost_events;
  if (!lost && health_.link_lost && have_state_) ++health_.reconnects;
  health_.link_lost = lost;
  health_.last_state_age_ns = have_state_ ? now_ns - last_state_rx_ns_ : -1;
  health_.last_heartbeat_age_ns = have_heartbeat_ ? now_ns - last_heartbeat_rx_ns_ : -1;
  return health_;
}

}  // namespace storey::drivers::go2
