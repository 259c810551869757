// The Go2's own interface: CycloneDDS (C API, idlc-generated types from drivers/go2/idl/).
// Reads rt/sportmodestate (pose, velocity, IMU, mode, gait, feet) and rt/lowstate (battery),
// writes sport requests on rt/api/sport/request (Move with noreply; StopMove, BalanceStand,
// StandUp, StandDown, Damp awaiting a response on rt/api/sport/response, counted if rejected).
// poll()/send_*() never block; CycloneDDS serialises each write on the caller's thread, which
// allocates inside the library (the UDP and CAN links do not).
#pragma once

#include <dds/dds.h>

#include <memory>
#include <string>

#include "drivers/go2/dds_config.hpp"
#include "drivers/go2/dds_domain.hpp"
#include "drivers/go2/link_monitor.hpp"

namespace storey::drivers::go2 {

struct DdsTopics {
  std::string sport_state = "rt/sportmodestate";
  std::string low_state = "rt/lowstate";
  std::string request = "rt/api/sport/request";
  std::string response = "rt/api/sport/response";
};

struct DdsLinkOptions {
  DdsNetworkOptions network;
  DdsTopics topics;
  LinkOptions link;
};

class DdsLink final : public RobotLink {
 public:
  DdsLink(const DdsLinkOptions& options, int64_t now_ns);
  ~DdsLink() override;

  bool ok() const override { return ok_; }
  const char* error() const override { return error_.c_str(); }
  const char* name() const override { return "dds"; }
  int poll(int64_t now_ns) override;
  const RobotState& latest_state() const override { return state_; }
  bool has_state() const override { return have_state_; }
  LinkStatus send_velocity(const VelocityCommand& cmd, int64_t now_ns) override;
  LinkStatus send_mode(const ModeCommand& cmd, int64_t now_ns) override;
  LinkHealth health(int64_t now_ns) override;

  // Number of matched subscribers of our request topic (the robot's sport service, or a
  // stand-in); 0 means requests currently go nowhere.
  int matched_request_readers() const;

 private:
  struct Samples;
  LinkStatus write_request(int64_t api_id, const char* parameter, bool noreply, int64_t now_ns);

  std::unique_ptr<DdsParticipant> participant_;
  std::unique_ptr<Samples> samples_;
  dds_entity_t sport_reader_ = 0;
  dds_entity_t low_reader_ = 0;
  dds_entity_t response_reader_ = 0;
  dds_entity_t request_writer_ = 0;
  LinkMonitor monitor_;
  RobotState state_;
  bool have_state_ = false;
  bool ok_ = false;
  std::string error_;
  int64_t last_request_id_ = 0;
};

}  // namespace storey::drivers::go2
