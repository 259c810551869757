// Hardware-in-the-loop world (`storey-sim --scene S --config FILE`, DESIGN §1, §7): the simulated
// robot in its world on a fixed-step loop paced to real time (or scaled by `rate`) with
// absolute-deadline sleeps. Each step (1 ms of simulated time = one robot physics step):
//   robot physics with the current command -> LiDAR packets whose shots are all in the past
//   (real VLP-16 / Mid-360 datagrams, sendmmsg from the sensor's address to the configured host
//   port) -> robot state published and commands drained over the configured Go2 link
//   (drivers/go2 robot stand-in: UDP or DDS) -> sleep until the step's deadline.
// One definition of each wire format serves both sides: the packets are encoded with
// drivers/lidar's encoders and the link is drivers/go2's stand-in, i.e. the decoders' own
// structs and channels. The loop runs on the thread that calls run(); nothing here creates
// threads; after construction the loop does not allocate (std::function calls aside).
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "config/parameters.hpp"
#include "tools/sim/hil_lidar_options.hpp"
#include "tools/sim/hil_mid360_source.hpp"
#include "tools/sim/hil_packet_sender.hpp"
#include "tools/sim/hil_robot_bridge.hpp"
#include "tools/sim/hil_vlp16_source.hpp"
#include "tools/sim/ray_caster.hpp"
#include "tools/sim/robot_model.hpp"
#include "tools/sim/scene.hpp"

namespace storey::tools::sim {

struct HilOptions {
  double rate = 1.0;      // simulated seconds per wall-clock second
  double duration = 0.0;  // [s] simulated time to run; 0 = until stopped
  uint64_t seed = 1;
  double step = 0.001;              // [s] simulated time per loop step (robot physics step)
  std::optional<StartPose> start;   // default: the scene's start pose
  double range_noise_sigma = 0.02;  // [m] LiDAR range noise
  double dropout = 0.0;             // LiDAR return dropout probability
  double state_rate_hz = 100.0;     // robot state publication rate on the link [Hz]
  double command_timeout_s = 0.5;   // no velocity command for this long -> robot stops [s]
  double body_height = 0.32;        // [m] Go2 body centre above the ground point
  double imu_rate_hz = 200.0;       // Mid-360 IMU packets (when sensor.imu_port != 0) [Hz]
  double progress_period_s = 1.0;   // wall-clock period of the progress callback [s]
};

struct HilStats {
  double sim_time_s = 0.0, wall_time_s = 0.0;
  uint64_t steps = 0;
  uint64_t lidar_packets = 0, lidar_returns = 0, imu_packets = 0;
  uint64_t send_errors = 0;  // datagrams the kernel refused or that did not fit a batch
  uint64_t velocity_commands = 0, mode_commands = 0, heartbeats = 0;
  uint64_t link_dropped = 0;      // malformed link frames
  uint64_t command_timeouts = 0;  // robot stopped for lack of commands
  uint64_t late_steps = 0;        // steps that ended after their deadline (no sleep)
  double max_lag_s = 0.0;         // worst lateness behind the schedule [s, wall]
  uint32_t collisions = 0, falls = 0, stuck_events = 0;
  double distance_m = 0.0;
};

class HilRunner {
 public:
  // Validates the configuration, builds the world and opens every socket. Throws
  // std::runtime_error with a one-line reason naming the setting (e.g. "link.transport: can ...").
  HilRunner(const Scene& scene, const config::Parameters& params, const HilOptions& options);
  ~HilRunner();

  // Runs until `stop` becomes true or `duration` of simulated time has passed. `progress` is
  // called on this thread every progress_period_s of wall time.
  void run(const std::atomic<bool>& stop,
           const std::function<void(const HilStats&)>& progress = {});

  // Statistics (read after run() returned, or inside the progress callback).
  const HilStats& stats() const { return stats_; }
  const RobotState& robot_state() const { return robot_->state(); }
  const std::vector<std::string>& warnings() const { return warnings_; }
  // Where things go, for the start-up banner and tests.
  std::string describe() const;
  uint16_t link_port() const { return bridge_->local_port(); }
  uint16_t lidar_source_port() const { return data_.bound_port(); }

 private:
  Eigen::Isometry3d pose_at(double t) const;
  void record_pose(double t);
  void send_imu(double t);
  void refresh_stats(int64_t wall_ns);

  config::Parameters params_;
  HilOptions opt_;
  std::unique_ptr<RayCaster> caster_;
  std::unique_ptr<RobotModel> robot_;
  HilLidarOptions lidar_opt_;
  std::unique_ptr<HilVlp16Source> vlp_;
  std::unique_ptr<HilMid360Source> mid_;
  HilPacketSender data_, imu_;
  std::unique_ptr<HilRobotBridge> bridge_;
  PoseAtTime pose_fn_;
  HilEmit emit_data_;
  // Body pose history (ring): enough for the longest look-back of a LiDAR packet (1.3 ms).
  struct Stamped {
    double t = 0.0;
    Eigen::Vector3d p{0, 0, 0};
    Eigen::Quaterniond q{1, 0, 0, 0};
  };
  static constexpr std::size_t kHistory = 256;
  std::vector<Stamped> history_;
  std::size_t history_head_ = 0, history_size_ = 0;
  double next_imu_t_ = 0.0;
  uint16_t imu_cnt_ = 0;
  int64_t sensor_epoch_ns_ = 0;  // CLOCK_REALTIME at simulated time 0
  std::string dest_, imu_dest_, link_desc_;
  std::vector<std::string> warnings_;
  HilStats stats_;
  int64_t wall_start_ns_ = 0;
};

}  // namespace storey::tools::sim
