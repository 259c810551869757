// One link interface for the firmware, whatever the transport (DDS, UDP, CAN, CAN-over-UDP).
// Called from one thread (the control task): poll() drains what arrived, latest_state() reads
// it, send_*() push commands. Nothing here blocks; times are passed in (CLOCK_MONOTONIC ns), so
// tests drive link-loss and staleness with injected times.
#pragma once

#include <cstdint>

#include "drivers/go2/robot_messages.hpp"

namespace storey::drivers::go2 {

enum class LinkStatus : uint8_t {
  ok = 0,
  stale_command,    // command timestamp older than LinkOptions::max_command_age_ns: not sent
  invalid_command,  // non-finite value or out-of-range mode: not sent
  would_block,      // socket buffer full: not sent (counted as a send error)
  send_failed,      // transport error: not sent (counted)
  not_open,         // the link failed to open (see error())
};

const char* to_string(LinkStatus s);

struct LinkOptions {
  // No state for longer than this -> link lost. Checked on every poll()/health() call, so with
  // the control task calling both each period the firmware learns of a loss at most one period
  // (20 ms) after the timeout.
  int64_t state_timeout_ns = 100'000'000;
  // A command whose stamp is older than this when send_*() is called is refused.
  int64_t max_command_age_ns = 40'000'000;
  // Host heartbeat period on links that carry one (UDP, CAN); sent from poll() when due.
  int64_t heartbeat_period_ns = 100'000'000;
};

// Health of a link as seen at `now`. Counters are totals since construction.
struct LinkHealth {
  int64_t last_state_age_ns = -1;  // now - receive time of the newest state; -1: none yet
  int64_t last_heartbeat_age_ns = -1;
  bool link_lost = true;          // no state for > state_timeout_ns (or none yet after it)
  uint64_t link_lost_events = 0;  // transitions ok -> lost (first timeout included)
  uint64_t reconnects = 0;        // transitions lost -> ok after a state arrived again
  uint64_t states_received = 0;
  uint64_t heartbeats_received = 0;
  uint64_t sequence_gaps = 0;  // messages missing according to sequence numbers
  uint64_t out_of_order = 0;   // older-than-newest messages dropped
  uint64_t crc_failures = 0;
  uint64_t decode_errors = 0;  // malformed frames/payloads, non-finite values
  uint64_t stale_commands_refused = 0;
  uint64_t invalid_commands_refused = 0;
  uint64_t send_errors = 0;
  uint64_t commands_sent = 0;
  uint64_t commands_rejected = 0;  // DDS: responses with a non-zero status code
  uint64_t rx_overflow_drops = 0;  // kernel receive-queue drops where the transport reports them
  uint64_t bus_errors = 0;         // CAN error frames
  uint64_t bus_off_events = 0;     // CAN bus-off
  uint64_t transport_reopens = 0;  // transport re-created after a fatal error (CAN bus-off)
};

class RobotLink {
 public:
  virtual ~RobotLink() = default;

  // False if construction failed; error() says why (interface, port, DDS return code...).
  virtual bool ok() const = 0;
  virtual const char* error() const = 0;
  virtual const char* name() const = 0;

  // Drains every received message without blocking; updates latest_state() and health.
  // Returns the number of new states.
  virtual int poll(int64_t now_ns) = 0;
  virtual const RobotState& latest_state() const = 0;
  virtual bool has_state() const = 0;

  // Refuses (and counts) a command older than max_command_age_ns at now_ns, or non-finite.
  virtual LinkStatus send_velocity(const VelocityCommand& cmd, int64_t now_ns) = 0;
  virtual LinkStatus send_mode(const ModeCommand& cmd, int64_t now_ns) = 0;

  virtual LinkHealth health(int64_t now_ns) = 0;
};

}  // namespace storey::drivers::go2
