// The firmware's Platform (firmware/platform.hpp) over the lockstep WorldSim: sweeps become
// ScanBuffers, odometry becomes PoseSamples, commands drive the simulated robot. step(dt)
// advances the world with the last command in force; the lockstep harness calls it between
// scheduler slices. Fault switches (LiDAR silent, pose frozen, link down) for the fault tests.
// Single-threaded like WorldSim.
#pragma once

#include "firmware/platform.hpp"
#include "tools/sim/world_sim.hpp"

namespace storey::tools::sim {

class SimPlatform final : public firmware::Platform {
 public:
  explicit SimPlatform(WorldSim& sim) : sim_(sim) {}

  // Advances the world by dt [s] with the command in force.
  void step(double dt) { sim_.step(dt, cmd_); }

  bool take_scan(firmware::ScanBuffer& out) override;
  bool latest_pose(firmware::PoseSample& out) override;
  void send_command(const firmware::VelocityCommand& cmd) override;
  firmware::LinkHealth link() override;

  // Fault injection. lidar_silent: sweeps are taken from the world and discarded;
  // pose_frozen: the last pose keeps being reported with its old stamp; link_down: commands
  // are lost (the robot keeps the last one it got, like a robot whose link died; its own
  // command timeout is not modelled) and the link reports disconnected.
  void set_lidar_silent(bool on) { lidar_silent_ = on; }
  void set_pose_frozen(bool on) { pose_frozen_ = on; }
  void set_link_down(bool on) { link_down_ = on; }

  const firmware::VelocityCommand& command() const { return fw_cmd_; }
  uint64_t commands() const { return commands_; }
  WorldSim& world() { return sim_; }

 private:
  WorldSim& sim_;
  VelocityCommand cmd_;
  firmware::VelocityCommand fw_cmd_;
  firmware::PoseSample frozen_;
  double frozen_link_s_ = -1;
  bool lidar_silent_ = false, pose_frozen_ = false, link_down_ = false;
  uint64_t commands_ = 0;
};

}  // namespace storey::tools::sim
