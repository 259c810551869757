#pragma once
// The stop conditions of the control task (DESIGN §3). Evaluated every control period from
// plain inputs; any active reason means the control task commands zero velocity in that same
// period. Reasons are a bit mask so several can hold at once; each rising edge is one event (the
// control task queues it for the non-RT log), and a stop (the mask leaving zero) is counted once
// in `safety_stops`. Motion resumes as soon as every reason has cleared.
//
// Start-up: until every input has been fresh once (first scan, first pose, first trajectory), the
// monitor is not armed: the robot is held still, but this is waiting, not a safety stop, and is
// neither logged nor counted (every run would otherwise start with one).
#include <cstdint>

#include "config/parameters.hpp"

namespace storey::firmware {

enum class StopReason : uint8_t {
  kLidarStale = 0,      // no LiDAR sweep for > lidar_stale_s
  kPoseStale,           // no odometry for > pose_stale_s
  kTrajectoryStale,     // the planner has not vouched for the trajectory for > trajectory_stale_s
  kLinkLoss,            // link down or no robot state for > link_timeout_s
  kPredictedCollision,  // FCL look-ahead hit within lookahead_s
  kOperatorStop,        // operator request
  kOverruns,            // control budget overruns beyond max_overruns
  kCount
};
const char* to_string(StopReason r);
inline constexpr uint32_t bit(StopReason r) {
  return 1u << uint32_t(r);
}

struct SafetyInputs {
  double now_s = 0;
  double last_scan_s = -1;           // < 0: none yet
  double pose_stamp_s = -1;          // < 0: none yet
  bool following = false;            // a trajectory is being tracked (not finished)
  double trajectory_vouched_s = -1;  // last time the planner confirmed the trajectory
  bool link_connected = true;
  double link_last_state_s = -1;  // < 0: never
  bool collision_predicted = false;
  bool operator_stop = false;
  bool overruns = false;  // the watchdog saw more than max_overruns in its window
};

struct SafetyDecision {
  uint32_t mask = 0;      // active reasons
  uint32_t raised = 0;    // reasons that became active in this evaluation
  uint32_t cleared = 0;   // reasons that cleared in this evaluation
  bool stop = false;      // command zero velocity (mask != 0, or not armed yet)
  bool new_stop = false;  // a stop started now (counted)
};

class SafetyMonitor {
 public:
  explicit SafetyMonitor(const config::SafetyConfig& cfg) : cfg_(cfg) {}
  SafetyDecision evaluate(const SafetyInputs& in);
  bool armed() const { return armed_; }
  uint32_t mask() const { return mask_; }
  uint64_t stops() const { return stops_; }  // stops since start (metrics: safety_stops)
  uint64_t events(StopReason r) const { return events_[int(r)]; }  // rising edges per reason

 private:
  config::SafetyConfig cfg_;
  bool armed_ = false;
  uint32_t mask_ = 0;
  uint64_t stops_ = 0;
  uint64_t events_[int(StopReason::kCount)] = {};
};

}  // namespace storey::firmware
