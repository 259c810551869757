// Shared bookkeeping behind every RobotLink's health(): state age, link-lost transitions,
// sequence gaps, command staleness. Pure computation, no I/O: unit-testable with injected times.
#pragma once

#include <cstdint>

#include "drivers/go2/robot_link.hpp"

namespace storey::drivers::go2 {

class LinkMonitor {
 public:
  LinkMonitor(const LinkOptions& options, int64_t start_ns);

  // Sequence check for a received message stream. Returns false if the message is older than
  // the newest seen (drop it); gaps are counted. A jump back by more than kRestartWindow is
  // taken as the peer restarting (sequence reset): accepted and resynchronised.
  enum class Stream : uint8_t { state = 0, heartbeat = 1 };
  bool accept_sequence(Stream stream, uint32_t seq);

  void on_state(int64_t rx_ns);
  void on_heartbeat(int64_t rx_ns);

  // Validates a command's age; counts refusals. ok or stale_command / invalid_command.
  LinkStatus check_command(int64_t stamp_ns, int64_t now_ns, bool finite);

  // Updates the link-lost flag at `now`; returns the health snapshot.
  LinkHealth update(int64_t now_ns);
  LinkHealth& counters() { return health_; }
  const LinkOptions& options() const { return options_; }

  static constexpr uint32_t kRestartWindow = 1000;

 private:
  LinkOptions options_;
  LinkHealth health_;
  int64_t start_ns_;
  int64_t last_state_rx_ns_ = 0;
  int64_t last_heartbeat_rx_ns_ = 0;
  bool have_state_ = false;
  bool have_heartbeat_ = false;
  bool have_seq_[2] = {false, false};
  uint32_t next_seq_[2] = {0, 0};
};

}  // namespace storey::drivers::go2
