// Shared helpers of the HIL tests: the analytic box room and a loopback configuration.
#pragma once

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "config/parameters.hpp"

namespace storey::tools::sim::test {

// Range from o along unit d to the inside of test_box_room (x 0.4..5.6, y 0.4..3.6, z 0..3).
inline double box_room_range(const Eigen::Vector3d& o, const Eigen::Vector3d& d) {
  const double lo[3] = {0.4, 0.4, 0.0}, hi[3] = {5.6, 3.6, 3.0};
  double t = 1e9;
  for (int a = 0; a < 3; ++a) {
    if (d[a] > 1e-12) t = std::min(t, (hi[a] - o[a]) / d[a]);
    if (d[a] < -1e-12) t = std::min(t, (lo[a] - o[a]) / d[a]);
  }
  return t;
}

// |p| minus the box room's range along p, for a point p in the frame of a sensor at `ws`.
inline double box_room_error(const Eigen::Isometry3d& ws, const Eigen::Vector3d& p) {
  const double r = p.norm();
  return r - box_room_range(ws.translation(), ws.linear() * (p / r));
}

// Everything on 127.0.0.1; ports 0 are filled in by the tests (ephemeral sockets).
inline config::Parameters loopback_params(config::SensorType type, int data_port) {
  config::Parameters p;
  p.sensor.type = type;
  p.sensor.sensor_address = "127.0.0.1";
  p.sensor.host_address = "127.0.0.1";
  p.sensor.data_port = data_port;
  p.sensor.imu_port = 0;
  p.link.transport = config::LinkTransport::kUdp;
  p.link.udp.robot_address = "127.0.0.1";
  p.link.udp.robot_port = 0;  // ephemeral: HilRunner::link_port()
  p.link.udp.local_address = "127.0.0.1";
  p.link.udp.local_port = 0;  // answer whoever sends (the test's UdpLink)
  return p;
}

// Sensor pose of the sim robot standing at the box room's start (3, 2, 0, yaw 0) with the
// config's default mount (0.28, 0, 0.12) above a 0.32 m body centre.
inline Eigen::Isometry3d box_room_sensor_pose() {
  return Eigen::Isometry3d(Eigen::Translation3d(3.0 + 0.28, 2.0, 0.12 + 0.32));
}

}  // namespace storey::tools::sim::test
