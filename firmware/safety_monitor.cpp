#include "firmware/safety_monitor.hpp"

namespace storey::firmware {

const char* to_string(StopReason r) {
  switch (r) {
    case StopReason::kLidarStale:
      return "lidar_stale";
    case StopReason::kPoseStale:
      return "pose_stale";
    case StopReason::kTrajectoryStale:
      return "trajectory_stale";
    case StopReason::kLinkLoss:
      return "link_loss";
    case StopReason::kPredictedCollision:
      return "predicted_collision";
    case StopReason::kOperatorStop:
      return "operator_stop";
    case StopReason::kOverruns:
      return "budget_overruns";
    case StopReason::kCount:
      break;
  }
  return "unknown";
}

SafetyDecision SafetyMonitor::evaluate(const SafetyInputs& in) {
  // "Older than" includes "never": an input that has not arrived is stale.
  auto stale = [&](double stamp, double limit) { return stamp < 0 || in.now_s - stamp > limit; };
  uint32_t m = 0;
  if (stale(in.last_scan_s, cfg_.lidar_stale_s)) m |= bit(StopReason::kLidarStale);
  if (stale(in.pose_stamp_s, cfg_.pose_stale_s)) m |= bit(StopReason::kPoseStale);
  if (in.following && stale(in.trajectory_vouched_s, cfg_.trajectory_stale_s))
    m |= bit(StopReason::kTrajectoryStale);
  if (!in.link_connected || stale(in.link_last_state_s, cfg_.link_timeout_s))
    m |= bit(StopReason::kLinkLoss);
  if (in.collision_predicted) m |= bit(StopReason::kPredictedCollision);
  if (in.operator_stop) m |= bit(StopReason::kOperatorStop);
  if (in.overruns) m |= bit(StopReason::kOverruns);

  SafetyDecision d;
  if (!armed_) {
    // Armed once the sensors, the link and the planner have all delivered (operator stop and
    // overruns do not hold arming back: they are stops in their own right once armed).
    const uint32_t startup =
        bit(StopReason::kLidarStale) | bit(StopReason::kPoseStale) | bit(StopReason::kLinkLoss);
    if ((m & startup) != 0 || in.trajectory_vouched_s < 0) {
      d.stop = true;
      return d;
    }
    armed_ = true;
  }
  d.mask = m;
  d.raised = m & ~mask_;
  d.cleared = mask_ & ~m;
  d.stop = m != 0;
  d.new_stop = m != 0 && mask_ == 0;
  for (int r = 0; r < int(StopReason::kCount); ++r)
    if (d.raised & (1u << r)) ++events_[r];
  if (d.new_stop) ++stops_;
  mask_ = m;
  return d;
}

}  // namespace storey::firmware
