// VLP-16 for hardware-in-the-loop: casts the firings of each 1206-byte data packet at their real
// times (16 lasers 2.304 us apart, one firing sequence per 55.296 us, 24 sequences per packet:
// ~754 packets/s at any spin rate) against the world, the robot moving underneath, and encodes
// them with drivers/lidar's VLP-16 encoder (the decoder's own structs).
//
// Why not the lockstep LidarModel: it casts whole sweeps after the robot has moved through them
// (100 ms late for real time) and turns counter-clockwise, while a real VLP-16 turns clockwise
// and the decoder refuses azimuths that run backwards. Here the head turns as the real one does:
// Velodyne azimuth a is clockwise from the sensor's +y axis, a laser at elevation w points along
// (cos w sin a, cos w cos a, sin w) in the sensor frame — exactly what vlp16_to_point() gives
// back, so the decoded points are in the sim's sensor (mount) frame. (Sim azimuth, CCW from +x,
// = 90 deg - a.) Each ray is cast along the azimuth the decoder will reconstruct from the packet
// (block azimuths in 0.01 deg, interpolated per laser), so decoding returns the cast point to
// within the 2 mm range unit.
#pragma once

#include <array>
#include <cstdint>

#include "drivers/lidar/vlp16.hpp"
#include "tools/sim/hil_lidar_options.hpp"
#include "tools/sim/lidar_model.hpp"
#include "tools/sim/ray_caster.hpp"
#include "tools/sim/rng.hpp"

namespace storey::tools::sim {

class HilVlp16Source {
 public:
  HilVlp16Source(const RayCaster& world, const HilLidarOptions& options);

  // Casts and emits every packet whose last firing is at or before simulated time t [s];
  // pose(t) must cover every time since the previous call. Returns packets emitted.
  int produce(double t, const PoseAtTime& pose, const HilEmit& emit);

  // Block azimuth [0.01 deg] of firing sequence `firing` (global count since time 0).
  uint16_t firing_azimuth(uint64_t firing) const;
  // Time [s] of the first laser of firing sequence `firing`.
  static double firing_time(uint64_t firing) { return double(firing) * 55.296e-6; }
  // Sensor clock [ns] at simulated time 0 (set before the first produce()).
  void set_clock_epoch(int64_t ns) { opt_.clock_epoch_ns = ns; }
  uint64_t packets() const { return next_packet_; }
  uint64_t returns() const { return returns_; }

 private:
  void cast_packet(uint64_t packet, const PoseAtTime& pose);

  const RayCaster& world_;
  HilLidarOptions opt_;
  Rng rng_;
  uint64_t next_packet_ = 0;
  uint64_t returns_ = 0;
  std::array<drivers::lidar::Vlp16Firing, drivers::lidar::kVlp16FiringsPerPacket> firings_{};
  std::array<uint8_t, drivers::lidar::kVlp16DataPacketSize> buf_{};
  std::array<float, 16> cos_el_{}, sin_el_{};
};

}  // namespace storey::tools::sim
