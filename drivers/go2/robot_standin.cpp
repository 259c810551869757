#include "drivers/go2/robot_standin.hpp"

#include <cmath>
#include <cstring>

#include "drivers/can/can_over_udp_transport.hpp"
#include "drivers/go2/dds_domain.hpp"
#include "drivers/go2/dds_go2_types.hpp"
#include "drivers/go2/sport_api.hpp"

namespace storey::drivers::go2 {
namespace {

// UDP and CAN-over-UDP: the same MessageChannel the firmware uses, in the robot role.
class FramedStandinEndpoint final : public StandinEndpoint {
 public:
  explicit FramedStandinEndpoint(std::unique_ptr<MessageChannel> ch) : ch_(std::move(ch)) {}
  bool ok() const override { return ch_->ok(); }
  const char* error() const override { return ch_->error(); }
  uint16_t local_port() const override { return ch_->local_port(); }

  bool receive(StandinCommand& out, uint64_t& dropped) override {
    ChannelMessage m;
    for (;;) {
      const RxStatus r = ch_->receive(m);
      if (r == RxStatus::empty || r == RxStatus::transport_error) return false;
      if (r != RxStatus::message) {
        ++dropped;
        continue;
      }
      out.sequence = m.header.sequence;
      switch (static_cast<MsgType>(m.header.type)) {
        case MsgType::velocity_command:
          out.kind = StandinCommand::Kind::velocity;
          if (decode_velocity(m.payload, m.payload_len, out.velocity) == PayloadError::ok) {
            return true;
          }
          break;
        case MsgType::mode_command:
          out.kind = StandinCommand::Kind::mode;
          if (decode_mode(m.payload, m.payload_len, out.mode) == PayloadError::ok) return true;
          break;
        case MsgType::heartbeat:
          out.kind = StandinCommand::Kind::heartbeat;
          if (decode_heartbeat(m.payload, m.payload_len, out.heartbeat) == PayloadError::ok) {
            return true;
          }
          break;
        default:
          break;
      }
      ++dropped;
    }
  }

  bool publish_state(const RobotState& s, int64_t now_ns) override {
    uint8_t p[kStatePayloadSize];
    encode_state(s, p);
    return send(MsgType::state, p, sizeof(p), now_ns);
  }

  bool publish_heartbeat(const Heartbeat& h, int64_t now_ns) override {
    uint8_t p[kHeartbeatPayloadSize];
    encode_heartbeat(h, p);
    return send(MsgType::heartbeat, p, sizeof(p), now_ns);
  }

 private:
  bool send(MsgType t, const uint8_t* p, size_t n, int64_t now_ns) {
    FrameHeader h;
    h.type = static_cast<uint8_t>(t);
    h.sequence = seq_[h.type & 7u]++;
    h.timestamp_ns = now_ns;
    return ch_->send(h, p, n) == LinkStatus::ok;
  }
  std::unique_ptr<MessageChannel> ch_;
  uint32_t seq_[8] = {};
};

// DDS: the robot's topics, as the Go2's sport service publishes and serves them.
class DdsStandinEndpoint final : public StandinEndpoint {
 public:
  DdsStandinEndpoint(const DdsNetworkOptions& net, const DdsTopics& topics) : participant_(net) {
    if (!participant_.ok()) {
      error_ = participant_.error();
      return;
    }
    const dds_entity_t pp = participant_.handle();
    const dds_entity_t t_sport = dds_create_topic(pp, &unitree_go_msg_dds__SportModeState__desc,
                                                  topics.sport_state.c_str(), nullptr, nullptr);
    const dds_entity_t t_low = dds_create_topic(pp, &unitree_go_msg_dds__LowState__desc,
                                                topics.low_state.c_str(), nullptr, nullptr);
    const dds_entity_t t_req = dds_create_topic(pp, &unitree_api_msg_dds__Request__desc,
                                                topics.request.c_str(), nullptr, nullptr);
    const dds_entity_t t_resp = dds_create_topic(pp, &unitree_api_msg_dds__Response__desc,
                                                 topics.response.c_str(), nullptr, nullptr);
    dds_qos_t* q = dds_create_qos();
    dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_MSECS(10));
    dds_qset_history(q, DDS_HISTORY_KEEP_LAST, 1);
    sport_writer_ = dds_create_writer(pp, t_sport, q, nullptr);
    low_writer_ = dds_create_writer(pp, t_low, q, nullptr);
    dds_qset_history(q, DDS_HISTORY_KEEP_LAST, 16);
    response_writer_ = dds_create_writer(pp, t_resp, q, nullptr);
    dds_qset_history(q, DDS_HISTORY_KEEP_LAST, 256);  // record every request
    request_reader_ = dds_create_reader(pp, t_req, q, nullptr);
    dds_delete_qos(q);
    if (sport_writer_ < 0 || low_writer_ < 0 || response_writer_ < 0 || request_reader_ < 0) {
      error_ = "DDS stand-in: creating writers/reader failed";
      return;
    }
    ok_ = true;
  }

  bool ok() const override { return ok_; }
  const char* error() const override { return error_.c_str(); }

  bool receive(StandinCommand& out, uint64_t& dropped) override {
    if (!ok_) return false;
    for (;;) {
      void* buf[1] = {nullptr};
      dds_sample_info_t info;
      const dds_return_t n = dds_take(request_reader_, buf, &info, 1, 1);
      if (n <= 0) return false;
      bool got = false;
      if (info.valid_data) {
        const auto* r = static_cast<const unitree_api_msg_dds__Request_*>(buf[0]);
        const int64_t api = r->header.identity.api_id;
        const char* param = r->parameter ? r->parameter : "";
        out.sequence = 0;
        if (api == kApiMove) {
          out.kind = StandinCommand::Kind::velocity;
          out.velocity.stamp_ns = r->header.identity.id;
          got = parse_move_parameter(param, std::strlen(param), out.velocity.vx, out.velocity.vy,
                                     out.velocity.yaw_rate);
        } else if (mode_for_api_id(api, out.mode.mode)) {
          out.kind = StandinCommand::Kind::mode;
          out.mode.stamp_ns = r->header.identity.id;
          got = true;
        }
        if (!r->header.policy.noreply) respond(r->header.identity, got ? 0 : 3104);
      }
      dds_return_loan(request_reader_, buf, n);
      if (got) return true;
      if (info.valid_data) ++dropped;
    }
  }

  bool publish_state(const RobotState& s, int64_t now_ns) override {
    unitree_go_msg_dds__SportModeState_ m{};
    m.stamp.sec = static_cast<int32_t>(s.stamp_ns / 1'000'000'000);
    m.stamp.nanosec = static_cast<uint32_t>(s.stamp_ns % 1'000'000'000);
    m.error_code = s.error_code;
    std::memcpy(m.imu_state.quaternion, s.quaternion.data(), sizeof(float) * 4);
    std::memcpy(m.imu_state.gyroscope, s.gyro.data(), sizeof(float) * 3);
    std::memcpy(m.imu_state.accelerometer, s.accel.data(), sizeof(float) * 3);
    std::memcpy(m.imu_state.rpy, s.rpy.data(), sizeof(float) * 3);
    m.mode = s.mode;
    m.gait_type = s.gait;
    std::memcpy(m.position, s.position.data(), sizeof(float) * 3);
    m.body_height = s.body_height;
    std::memcpy(m.velocity, s.velocity.data(), sizeof(float) * 3);
    m.yaw_speed = s.yaw_speed;
    for (int i = 0; i < 4; ++i) m.foot_force[i] = s.foot_force[i];
    const bool a = dds_write(sport_writer_, &m) == DDS_RETCODE_OK;
    unitree_go_msg_dds__LowState_ l{};
    l.head[0] = 0xFE;
    l.head[1] = 0xEF;
    l.imu_state = m.imu_state;
    l.bms_state.soc = s.battery_soc;
    for (int i = 0; i < 4; ++i) l.foot_force[i] = s.foot_force[i];
    l.power_v = s.battery_voltage;
    l.power_a = s.battery_current;
    const bool b = dds_write(low_writer_, &l) == DDS_RETCODE_OK;
    (void)now_ns;
    return a && b;
  }

 private:
  void respond(const unitree_api_msg_dds__RequestIdentity_& id, int32_t code) {
    unitree_api_msg_dds__Response_ r{};
    r.header.identity = id;
    r.header.status.code = code;
    r.data = const_cast<char*>("");
    dds_write(response_writer_, &r);
  }

  DdsParticipant participant_;
  dds_entity_t sport_writer_ = 0, low_writer_ = 0, response_writer_ = 0, request_reader_ = 0;
  bool ok_ = false;
  std::string error_;
};

}  // namespace

RobotStandin::RobotStandin(const StandinOptions& options, int64_t now_ns)
    : options_(options),
      last_integrate_ns_(now_ns),
      next_state_ns_(now_ns),
      next_heartbeat_ns_(now_ns) {
  switch (options.transport) {
    case StandinTransport::dds:
      endpoint_ = std::make_unique<DdsStandinEndpoint>(options.dds, options.topics);
      break;
    case StandinTransport::udp:
      endpoint_ = std::make_unique<FramedStandinEndpoint>(
          std::make_unique<UdpChannel>(Role::robot, options.local, options.host));
      break;
    case StandinTransport::can_over_udp:
      endpoint_ = std::make_unique<FramedStandinEndpoint>(std::make_unique<CanChannel>(
          Role::robot, std::make_unique<can::CanOverUdpTransport>(options.local, options.host),
          options.can));
      break;
  }
  state_.mode = static_cast<uint8_t>(RobotModeId::balance_stand);
  state_.body_height = 0.32f;
  state_.battery_voltage = 28.8f;
  state_.battery_soc = 90;
}

RobotStandin::~RobotStandin() = default;

bool RobotStandin::ok() const {
  return endpoint_ && endpoint_->ok();
}
const char* RobotStandin::error() const {
  return endpoint_ ? endpoint_->error() : "no endpoint";
}

void RobotStandin::set_state(const RobotState& s) {
  state_ = s;
  options_.integrate = false;
}

void RobotStandin::apply(const StandinCommand& c) {
  switch (c.kind) {
    case StandinCommand::Kind::velocity:
      ++velocity_commands_;
      last_velocity_ = c;
      have_velocity_ = true;
      break;
    case StandinCommand::Kind::mode:
      ++mode_commands_;
      last_mode_ = c;
      have_velocity_ = false;  // every mode request ends the current motion
      if (options_.integrate) {
        switch (c.mode.mode) {
          case ModeRequest::stop:
          case ModeRequest::balance_stand:
          case ModeRequest::stand_up:
            state_.mode = static_cast<uint8_t>(RobotModeId::balance_stand);
            break;
          case ModeRequest::stand_down:
            state_.mode = static_cast<uint8_t>(RobotModeId::lie_down);
            break;
          case ModeRequest::damp:
            state_.mode = static_cast<uint8_t>(RobotModeId::damping);
            break;
        }
      }
      break;
    case StandinCommand::Kind::heartbeat:
      ++heartbeats_;
      break;
  }
}

void RobotStandin::integrate(int64_t now_ns) {
  const double dt = static_cast<double>(now_ns - last_integrate_ns_) * 1e-9;
  last_integrate_ns_ = now_ns;
  if (dt <= 0.0) return;
  float vx = 0, vy = 0, wz = 0;
  const bool can_move = state_.mode == static_cast<uint8_t>(RobotModeId::balance_stand) ||
                        state_.mode == static_cast<uint8_t>(RobotModeId::locomotion);
  if (have_velocity_ && can_move && now_ns - last_velocity_.rx_ns <= options_.command_timeout_ns) {
    vx = last_velocity_.velocity.vx;
    vy = last_velocity_.velocity.vy;
    wz = last_velocity_.velocity.yaw_rate;
  }
  if (can_move) {
    const bool moving = vx != 0 || vy != 0 || wz != 0;
    state_.mode =
        static_cast<uint8_t>(moving ? RobotModeId::locomotion : RobotModeId::balance_stand);
    state_.gait = static_cast<uint8_t>(moving ? GaitId::trot : GaitId::idle);
  }
  // Body velocity rotated into the odometry frame (unicycle with lateral slip).
  const float c = std::cos(yaw_), s = std::sin(yaw_);
  const float wx = c * vx - s * vy, wy = s * vx + c * vy;
  state_.position[0] += static_cast<float>(wx * dt);
  state_.position[1] += static_cast<float>(wy * dt);
  yaw_ = static_cast<float>(std::remainder(yaw_ + wz * dt, 2.0 * M_PI));
  state_.velocity = {wx, wy, 0.0f};
  state_.yaw_speed = wz;
  state_.rpy = {0.0f, 0.0f, yaw_};
  state_.quaternion = {std::cos(yaw_ / 2), 0.0f, 0.0f, std::sin(yaw_ / 2)};
  state_.gyro = {0.0f, 0.0f, wz};
  state_.accel = {0.0f, 0.0f, 9.81f};
}

int RobotStandin::step(int64_t now_ns) {
  if (!ok()) return 0;
  int n = 0;
  StandinCommand c;
  while (endpoint_->receive(c, dropped_)) {
    c.rx_ns = now_ns;
    apply(c);
    if (on_command) on_command(c);
    ++n;
  }
  if (options_.integrate) integrate(now_ns);
  if (now_ns >= next_state_ns_) {
    next_state_ns_ = now_ns + options_.state_period_ns;
    publish_now(now_ns);
  }
  if (now_ns >= next_heartbeat_ns_) {
    next_heartbeat_ns_ = now_ns + options_.heartbeat_period_ns;
    Heartbeat h;
    h.stamp_ns = now_ns;
    h.counter = heartbeat_counter_++;
    endpoint_->publish_heartbeat(h, now_ns);
  }
  return n;
}

bool RobotStandin::publish_now(int64_t now_ns) {
  state_.stamp_ns = now_ns;
  return endpoint_->publish_state(state_, now_ns);
}

}  // namespace storey::drivers::go2
