#pragma once
// storey::config::Parameters: the whole configuration as typed structs, and the loader that
// fills it from YAML (validated; every error names file, key and line). The algorithm option
// structs live in core/ (their defaults are the paper's starting values, DESIGN.md §4); the
// deployment sections (sensor, rates, safety, link, realtime) are defined here.
#include <array>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "config/yaml_reader.hpp"
#include "core/graph/graph_options.hpp"
#include "core/map/map_options.hpp"
#include "core/plan/plan_options.hpp"
#include "core/robot_model.hpp"

namespace storey::config {

enum class SensorType { kVlp16, kMid360 };

// The LiDAR, its mounting on the robot and where its UDP packets arrive.
struct SensorConfig {
  SensorType type = SensorType::kVlp16;
  // Sensor origin in the body frame (x forward, y left, z up) [m] and its orientation
  // (roll, pitch, yaw about fixed x, y, z) [rad]; YAML gives the angles in degrees.
  std::array<double, 3> mounting_xyz_m{0.28, 0.0, 0.12};
  std::array<double, 3> mounting_rpy_rad{0.0, 0.0, 0.0};
  double min_range_m = 0.3;    // closer returns are the robot itself
  double max_range_m = 100.0;  // beyond the sensor's rated range returns are noise
  double scan_rate_hz = 10.0;  // one scan = one revolution (VLP-16) / frame (Mid-360)
  std::string sensor_address = "192.168.1.201";  // packets from other sources are dropped; "" = any
  std::string host_address = "0.0.0.0";          // local address the socket binds to
  int data_port = 2368;                          // point data UDP port (VLP-16 2368, Mid-360 56301)
  int imu_port = 0;                              // Mid-360 IMU UDP port (56401); 0 = not used
  int rcvbuf_bytes = 8 << 20;                    // SO_RCVBUF: ~1 s of packets at 2x the rate
};

// One row of the scheduler's task table (ArduPilot style: rate, budget, priority, CPU).
struct TaskRate {
  double rate_hz = 0.0;  // 0 = event-driven (runs when its socket becomes readable)
  int budget_us = 0;     // execution-time budget per run; longer runs count as overruns
  int priority = 0;      // SCHED_FIFO priority 1..99 when realtime.sched_fifo; 0 = SCHED_OTHER
  int cpu = -1;          // CPU to pin to when realtime.cpu_pinning; -1 = any
};

// The task table (DESIGN.md §3): figures are starting points, measured in docs/PERFORMANCE.md.
struct RateTable {
  TaskRate ingest{0.0, 2000, 80, -1};     // LiDAR UDP -> point chunks, per readable event
  TaskRate map{10.0, 50000, 60, -1};      // raycast, traversability, graph + frontiers
  TaskRate plan{2.0, 200000, 40, -1};     // zones, TSP, DP, A*, B-spline
  TaskRate control{50.0, 2000, 90, -1};   // tracking, look-ahead collision check, safety
  TaskRate watchdog{10.0, 500, 95, -1};   // liveness of the other tasks and the link
  TaskRate telemetry{1.0, 10000, 0, -1};  // status, latency reports

  struct Row {
    std::string_view name;
    const TaskRate* rate;
  };
  std::array<Row, 6> rows() const {
    return {{{"ingest", &ingest},
             {"map", &map},
             {"plan", &plan},
             {"control", &control},
             {"watchdog", &watchdog},
             {"telemetry", &telemetry}}};
  }
};

// Conditions under which the control task commands a stop (DESIGN.md §3).
struct SafetyConfig {
  double lidar_stale_s = 0.3;       // no LiDAR data for longer -> stop
  double pose_stale_s = 0.1;        // no pose for longer -> stop
  double trajectory_stale_s = 1.5;  // trajectory older than this (3 plan periods) -> stop
  double link_timeout_s = 0.25;     // no robot state over the link for longer -> stop
  double lookahead_s = 1.0;         // predicted collision within this horizon -> stop
  int max_overruns = 3;             // consecutive control-task budget overruns -> stop
  // Session 13 switches, off in the structs (docs/RESULTS.md session 13): each fixes a failure it
  // was measured on, and each moved which seeds end with a floor unreached. config/default.yaml
  // turns both on (lookahead_on_plan_grid since session 18, turn_on_reference since 41).
  // Turn only where the robot will come to rest on the reference or on the path it came along
  // (ControlLaw::yaw_gate): a robot overshooting a new trajectory's start turned its body into a
  // door frame.
  bool turn_on_reference = false;
  // ... "on the reference": the rest point within the first distance of the reference's gives
  // full yaw authority, falling to none at the second (ControlLaw::on_reference) [m]. A body
  // 0.15-0.23 m past a turn-in-place start turned into a wall with 0.15 / 0.3 (office
  // nearest-frontier seed 5, sessions 42-43); 0.05 / 0.15 held another body's yaw while its
  // reference turned, into a wall (seed 1, session 44).
  double turn_on_reference_full_m = 0.15;
  double turn_on_reference_zero_m = 0.3;
  // The look-ahead samples the poses of the planner's own check (check_on_grid) and asks for a
  // replan on every new trajectory it finds colliding: sampled from tau, it failed a pose the
  // planner passed, and the robot stood stopped on a kept trajectory for 400 s (house seed 6).
  bool lookahead_on_plan_grid = false;
  // The reference slows for a yaw error above this and waits from twice it
  // (ControlLaw::progress_rate) [rad].
  double reference_yaw_gate_rad = 0.6;
  // The reference moves at most this much faster than the robot along it
  // (ControlLaw::speed_rate): a trajectory entered mid-way at walking speed by a robot braked
  // nearly to rest ran 0.3 m ahead round a bend, and the body cut it into a wall (house seed 1,
  // session 32). 0: off [m/s].
  double reference_speed_lead_mps = 0.0;
  // The look-ahead also checks the poses the body sweeps as it closes its yaw error to the
  // reference (ControlLaw::turn_poses) at its own position: a body 0.15 m off a new trajectory's
  // start turned 0.3 rad towards it into a door jamb, between poses each checked at the
  // reference's position (office seed 2, session 40). A turn that would collide is held while
  // the body slides onto its reference, if that and the turn there are clear
  // (ControlLaw::slide_poses); else stop and replan. Off (session 41): stop-and-replan alone used
  // up the trips to the teaching building's U-stair (seed 2, "complete" downstairs).
  bool check_body_turn = false;
};

enum class LinkTransport { kDds, kUdp, kCan, kSim };

struct DdsLinkConfig {
  int domain_id = 0;               // the Go2 uses DDS domain 0
  std::string interface = "";      // network interface for CycloneDDS; "" = its own choice
  bool allow_multicast = true;     // multicast discovery (robot network); false: unicast to peers
  std::vector<std::string> peers;  // unicast discovery peers, e.g. {"127.0.0.1"}
};
struct UdpLinkConfig {
  std::string robot_address = "127.0.0.1";  // where commands go
  int robot_port = 17001;
  std::string local_address = "0.0.0.0";  // where robot state arrives
  int local_port = 17002;
};
struct CanLinkConfig {
  std::string interface = "can0";  // SocketCAN interface
  bool fd_frames = false;          // send CAN FD frames (receive accepts both)
};

// How velocity commands reach the robot and its state comes back.
struct LinkConfig {
  LinkTransport transport = LinkTransport::kSim;  // sim = in-process lockstep simulator
  double max_command_age_s = 0.04;  // older commands are refused by the link, not sent
  double heartbeat_period_s = 0.1;  // host heartbeat on links that carry one (UDP, CAN)
  DdsLinkConfig dds;
  UdpLinkConfig udp;
  CanLinkConfig can;
};

// Real-time setup of the process; each degrades with one warning where not permitted.
struct RealtimeConfig {
  bool sched_fifo = false;   // SCHED_FIFO with the task table's priorities
  bool mlockall = false;     // lock current and future pages (no page faults in tasks)
  bool cpu_pinning = false;  // pin each task thread to its task table CPU
};

struct Parameters {
  core::RobotModel robot;
  core::map::MapOptions map;
  core::graph::GraphOptions graph;
  core::plan::PlanOptions plan;
  SensorConfig sensor;
  RateTable rates;
  SafetyConfig safety;
  LinkConfig link;
  RealtimeConfig realtime;
};

// The outcome of a load: the parameters (defaults wherever a value was missing or bad) and
// every error found. Only use `params` when ok().
struct Result {
  Parameters params;
  std::vector<ConfigError> errors;
  std::vector<std::string> files;           // every file read, base layers first
  std::map<std::string, Location> origins;  // where each given value was last set
  std::vector<std::string> schema_keys;     // every key the schema knows (dotted paths)
  bool ok() const { return errors.empty(); }
};

// Loads a configuration file and the files it includes (`include: base.yaml` or a list,
// relative to the including file; the including file overrides what they set).
Result load(const std::string& path);
// Same, from text; `name` stands for the file in messages and anchors relative includes.
Result load_string(std::string_view text, const std::string& name);

std::string_view to_string(SensorType t);
std::string_view to_string(LinkTransport t);

}  // namespace storey::config
