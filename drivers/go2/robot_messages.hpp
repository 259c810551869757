// Transport-independent message model of the Go2 link: what the firmware reads from the robot
// and what it commands. Every link (DDS, UDP, CAN) converts to and from these structs, so the
// control and safety logic never sees a transport. Units are SI; times are CLOCK_MONOTONIC ns.
#pragma once

#include <array>
#include <cstdint>

namespace storey::drivers::go2 {

// Sport-mode state reported by the robot (Go2 SportModeState_ mode numbering).
enum class RobotModeId : uint8_t {
  idle = 0,
  balance_stand = 1,
  locomotion = 3,
  lie_down = 5,
  damping = 7,
  recovery_stand = 8,
};

// Gait reported by the robot (Go2 SportModeState_ gait_type numbering).
enum class GaitId : uint8_t { idle = 0, trot = 1, run = 2, climb_stair = 3, down_stair = 4 };

// Robot state: pose/velocity from the robot's own odometry, IMU, foot contacts, battery.
// PX4 habit: two times, when the robot sampled it (its clock) and when we received it (ours).
struct RobotState {
  int64_t stamp_ns = 0;             // sample time, sender's clock [ns]
  int64_t rx_stamp_ns = 0;          // receive time, our CLOCK_MONOTONIC [ns] (set by link)
  std::array<float, 3> position{};  // odometry frame [m]
  std::array<float, 3> velocity{};  // [m/s]
  float yaw_speed = 0.0f;           // [rad/s]
  float body_height = 0.0f;         // [m]
  std::array<float, 4> quaternion{1.0f, 0.0f, 0.0f, 0.0f};  // w, x, y, z
  std::array<float, 3> gyro{};                              // [rad/s]
  std::array<float, 3> accel{};                             // [m/s^2]
  std::array<float, 3> rpy{};                               // roll, pitch, yaw [rad]
  uint8_t mode = 0;                     // RobotModeId value as reported (unknown values kept)
  uint8_t gait = 0;                     // GaitId value as reported
  std::array<int16_t, 4> foot_force{};  // FR, FL, RR, RL raw sensor units
  float battery_voltage = 0.0f;         // [V]
  float battery_current = 0.0f;         // [A]
  uint8_t battery_soc = 0;              // state of charge [%]
  uint32_t error_code = 0;              // robot's error code, 0 = none
};

// Body velocity command in the robot's body frame.
struct VelocityCommand {
  int64_t stamp_ns = 0;   // when the command was computed, CLOCK_MONOTONIC [ns]
  float vx = 0.0f;        // forward [m/s]
  float vy = 0.0f;        // left [m/s]
  float yaw_rate = 0.0f;  // counter-clockwise [rad/s]
};

// Discrete motion requests (Go2 sport API: StopMove 1003, BalanceStand 1002, StandUp 1004,
// StandDown 1005, Damp 1001).
enum class ModeRequest : uint8_t {
  stop = 0,
  balance_stand = 1,
  stand_up = 2,
  stand_down = 3,
  damp = 4,
};
inline constexpr uint8_t kModeRequestCount = 5;

struct ModeCommand {
  int64_t stamp_ns = 0;  // CLOCK_MONOTONIC [ns]
  ModeRequest mode = ModeRequest::stop;
};

// Liveness message, sent both ways on the UDP and CAN links.
struct Heartbeat {
  int64_t stamp_ns = 0;  // sender's clock [ns]
  uint32_t counter = 0;  // increments by one per heartbeat
  uint8_t status = 0;    // bit 0: sender considers the link lost
};

inline const char* to_string(ModeRequest m) {
  switch (m) {
    case ModeRequest::stop:
      return "stop";
    case ModeRequest::balance_stand:
      return "balance_stand";
    case ModeRequest::stand_up:
      return "stand_up";
    case ModeRequest::stand_down:
      return "stand_down";
    case ModeRequest::damp:
      return "damp";
  }
  return "invalid";
}

}  // namespace storey::drivers::go2
