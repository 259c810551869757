#pragma once
// What the firmware needs from "robot + sensors" (DESIGN §3), and nothing more: the next LiDAR
// sweep, the latest odometry, a velocity command out, and the health of the robot link. The
// lockstep simulator implements it in tools/sim/sim_platform.hpp; the live robot (drivers/lidar +
// drivers/go2) will implement it for `storey run`. Times are seconds on the firmware clock's
// timeline (the scheduler's clock: virtual in sim, monotonic live).
#include <cmath>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

namespace storey::firmware {

// The Go2's body centre stands this far above its feet; the robot reports the centre's position
// and the sensor mounting is given relative to it.
inline constexpr double kBodyCentreHeightM = 0.32;

// One sweep in the world (odometry) frame, deskewed by the platform. A pool buffer: its vectors
// keep their capacity between sweeps, so steady-state ingestion does not allocate.
struct ScanBuffer {
  double stamp_s = 0;                                  // end of the sweep [s]
  Eigen::Vector3f origin_m = Eigen::Vector3f::Zero();  // sensor origin at the sweep's end [m]
  std::vector<Eigen::Vector3f> points_m;               // returns, world frame [m]
  void clear() { points_m.clear(); }
};

// Odometry sample (trivially copyable: travels through rt::Mailbox).
struct PoseSample {
  double stamp_s = -1;               // when the robot measured it [s]; < 0: none yet
  double x_m = 0, y_m = 0, z_m = 0;  // ground point under the body centre [m]
  double yaw_rad = 0;
  double vx_mps = 0, vy_mps = 0, yaw_rate_rps = 0;  // body frame
  Eigen::Vector3d position() const { return {x_m, y_m, z_m}; }
  Eigen::Vector2d velocity_world() const {  // planar velocity, body -> world frame
    const double c = std::cos(yaw_rad), s = std::sin(yaw_rad);
    return {c * vx_mps - s * vy_mps, s * vx_mps + c * vy_mps};
  }
};

// Body-frame velocity command (x forward, y left) [m/s], yaw rate [rad/s].
struct VelocityCommand {
  double stamp_s = 0;  // when the control task issued it [s]
  double vx_mps = 0, vy_mps = 0, yaw_rate_rps = 0;
  bool is_zero() const { return vx_mps == 0 && vy_mps == 0 && yaw_rate_rps == 0; }
};

struct LinkHealth {
  bool connected = true;     // false: the transport reports the link down
  double last_state_s = -1;  // when the last robot state arrived [s]; < 0: never
};

class Platform {
 public:
  virtual ~Platform() = default;
  // Ingest task: moves the next complete sweep into `out` (reusing its capacity); false if none.
  virtual bool take_scan(ScanBuffer& out) = 0;
  // Control task: the latest odometry; false if none has arrived yet.
  virtual bool latest_pose(PoseSample& out) = 0;
  // Control task: the command in force until the next one.
  virtual void send_command(const VelocityCommand& cmd) = 0;
  // Control task: link liveness.
  virtual LinkHealth link() = 0;
};

}  // namespace storey::firmware
