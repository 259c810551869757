#include "drivers/go2/dds_link.hpp"

#include <cmath>
#include <cstring>

#include "drivers/go2/dds_go2_types.hpp"
#include "drivers/go2/sport_api.hpp"

namespace storey::drivers::go2 {

struct DdsLink::Samples {
  unitree_go_msg_dds__SportModeState_ sport{};
  unitree_go_msg_dds__LowState_ low{};
};

DdsLink::DdsLink(const DdsLinkOptions& options, int64_t now_ns)
    : samples_(std::make_unique<Samples>()), monitor_(options.link, now_ns) {
  participant_ = std::make_unique<DdsParticipant>(options.network);
  if (!participant_->ok()) {
    error_ = participant_->error();
    return;
  }
  const dds_entity_t pp = participant_->handle();
  auto fail = [&](const char* what, dds_return_t rc) {
    error_ = std::string(what) + ": " + dds_strretcode(rc);
  };
  const dds_entity_t t_sport =
      dds_create_topic(pp, &unitree_go_msg_dds__SportModeState__desc,
                       options.topics.sport_state.c_str(), nullptr, nullptr);
  const dds_entity_t t_low = dds_create_topic(pp, &unitree_go_msg_dds__LowState__desc,
                                              options.topics.low_state.c_str(), nullptr, nullptr);
  const dds_entity_t t_req = dds_create_topic(pp, &unitree_api_msg_dds__Request__desc,
                                              options.topics.request.c_str(), nullptr, nullptr);
  const dds_entity_t t_resp = dds_create_topic(pp, &unitree_api_msg_dds__Response__desc,
                                               options.topics.response.c_str(), nullptr, nullptr);
  if (t_sport < 0 || t_low < 0 || t_req < 0 || t_resp < 0) {
    fail("dds_create_topic", t_sport < 0 ? t_sport
                             : t_low < 0 ? t_low
                             : t_req < 0 ? t_req
                                         : t_resp);
    return;
  }
  // Readers best-effort keep-last-1: match the robot's writers whatever their reliability, and
  // only the newest state matters. Writer reliable: matches best-effort and reliable readers.
  dds_qos_t* rq = dds_create_qos();
  dds_qset_reliability(rq, DDS_RELIABILITY_BEST_EFFORT, 0);
  dds_qset_history(rq, DDS_HISTORY_KEEP_LAST, 1);
  sport_reader_ = dds_create_reader(pp, t_sport, rq, nullptr);
  low_reader_ = dds_create_reader(pp, t_low, rq, nullptr);
  dds_qset_history(rq, DDS_HISTORY_KEEP_LAST, 16);
  response_reader_ = dds_create_reader(pp, t_resp, rq, nullptr);
  dds_delete_qos(rq);
  dds_qos_t* wq = dds_create_qos();
  dds_qset_reliability(wq, DDS_RELIABILITY_RELIABLE, DDS_MSECS(10));
  dds_qset_history(wq, DDS_HISTORY_KEEP_LAST, 1);
  request_writer_ = dds_create_writer(pp, t_req, wq, nullptr);
  dds_delete_qos(wq);
  if (sport_reader_ < 0 || low_reader_ < 0 || response_reader_ < 0) {
    fail("dds_create_reader", sport_reader_ < 0 ? sport_reader_
                              : low_reader_ < 0 ? low_reader_
                                                : response_reader_);
    return;
  }
  if (request_writer_ < 0) {
    fail("dds_create_writer", request_writer_);
    return;
  }
  ok_ = true;
}

DdsLink::~DdsLink() = default;  // deleting the participant deletes its readers and writers

int DdsLink::poll(int64_t now_ns) {
  if (!ok_) return 0;
  int states = 0;
  LinkHealth& h = monitor_.counters();
  dds_sample_info_t info;
  // Fixed-size types: take() deserialises into our preallocated sample, no allocation.
  for (int i = 0; i < 64; ++i) {
    void* buf[1] = {&samples_->sport};
    const dds_return_t n = dds_take(sport_reader_, buf, &info, 1, 1);
    if (n <= 0) break;
    if (!info.valid_data) continue;
    const auto& s = samples_->sport;
    RobotState r = state_;  // keeps the battery fields from rt/lowstate
    r.stamp_ns = static_cast<int64_t>(s.stamp.sec) * 1'000'000'000 + s.stamp.nanosec;
    r.rx_stamp_ns = now_ns;
    bool finite = true;
    auto copy = [&finite](const float* src, float* dst, int n) {
      for (int k = 0; k < n; ++k) {
        dst[k] = src[k];
        finite = finite && std::isfinite(src[k]);
      }
    };
    copy(s.position, r.position.data(), 3);
    copy(s.velocity, r.velocity.data(), 3);
    copy(&s.yaw_speed, &r.yaw_speed, 1);
    copy(&s.body_height, &r.body_height, 1);
    copy(s.imu_state.quaternion, r.quaternion.data(), 4);
    copy(s.imu_state.gyroscope, r.gyro.data(), 3);
    copy(s.imu_state.accelerometer, r.accel.data(), 3);
    copy(s.imu_state.rpy, r.rpy.data(), 3);
    if (!finite) {
      ++h.decode_errors;  // never let a NaN pose into the map
      continue;
    }
    r.mode = s.mode;
    r.gait = s.gait_type;
    for (int k = 0; k < 4; ++k) r.foot_force[k] = s.foot_force[k];
    r.error_code = s.error_code;
    state_ = r;
    have_state_ = true;
    monitor_.on_state(now_ns);
    ++states;
  }
  for (int i = 0; i < 64; ++i) {
    void* buf[1] = {&samples_->low};
    const dds_return_t n = dds_take(low_reader_, buf, &info, 1, 1);
    if (n <= 0) break;
    if (!info.valid_data) continue;
    const auto& l = samples_->low;
    if (!std::isfinite(l.power_v) || !std::isfinite(l.power_a)) {
      ++h.decode_errors;
      continue;
    }
    state_.battery_voltage = l.power_v;
    state_.battery_current = l.power_a;
    state_.battery_soc = l.bms_state.soc;
  }
  // Responses carry strings: take with loans, return them at once.
  for (int i = 0; i < 16; ++i) {
    void* buf[1] = {nullptr};
    const dds_return_t n = dds_take(response_reader_, buf, &info, 1, 1);
    if (n <= 0) break;
    if (info.valid_data) {
      const auto* r = static_cast<const unitree_api_msg_dds__Response_*>(buf[0]);
      if (r->header.status.code != 0) ++h.commands_rejected;
    }
    dds_return_loan(response_reader_, buf, n);
  }
  dds_sample_lost_status_t lost{};
  if (dds_get_sample_lost_status(sport_reader_, &lost) == DDS_RETCODE_OK) {
    h.sequence_gaps += lost.total_count_change;
  }
  monitor_.update(now_ns);
  return states;
}

LinkStatus DdsLink::write_request(int64_t api_id, const char* parameter, bool noreply,
                                  int64_t now_ns) {
  unitree_api_msg_dds__Request_ req{};
  // Identity id: unique and increasing; the send time, so the receiver can tell its age.
  last_request_id_ = now_ns > last_request_id_ ? now_ns : last_request_id_ + 1;
  req.header.identity.id = last_request_id_;
  req.header.identity.api_id = api_id;
  req.header.lease.id = 0;
  req.header.policy.priority = 0;
  req.header.policy.noreply = noreply;
  req.parameter = const_cast<char*>(parameter);
  req.binary._length = 0;
  req.binary._maximum = 0;
  req.binary._buffer = nullptr;
  req.binary._release = false;
  const dds_return_t rc = dds_write(request_writer_, &req);
  LinkHealth& h = monitor_.counters();
  if (rc != DDS_RETCODE_OK) {
    ++h.send_errors;
    return LinkStatus::send_failed;
  }
  ++h.commands_sent;
  return LinkStatus::ok;
}

LinkStatus DdsLink::send_velocity(const VelocityCommand& cmd, int64_t now_ns) {
  if (!ok_) return LinkStatus::not_open;
  const bool finite = std::isfinite(cmd.vx) && std::isfinite(cmd.vy) && std::isfinite(cmd.yaw_rate);
  const LinkStatus c = monitor_.check_command(cmd.stamp_ns, now_ns, finite);
  if (c != LinkStatus::ok) return c;
  char json[96];
  if (format_move_parameter(cmd.vx, cmd.vy, cmd.yaw_rate, json, sizeof(json)) == 0) {
    return LinkStatus::invalid_command;
  }
  return write_request(kApiMove, json, /*noreply=*/true, now_ns);
}

LinkStatus DdsLink::send_mode(const ModeCommand& cmd, int64_t now_ns) {
  if (!ok_) return LinkStatus::not_open;
  const bool valid = static_cast<uint8_t>(cmd.mode) < kModeRequestCount;
  const LinkStatus c = monitor_.check_command(cmd.stamp_ns, now_ns, valid);
  if (c != LinkStatus::ok) return c;
  return write_request(api_id_for(cmd.mode), "{}", /*noreply=*/false, now_ns);
}

LinkHealth DdsLink::health(int64_t now_ns) {
  return monitor_.update(now_ns);
}

int DdsLink::matched_request_readers() const {
  dds_publication_matched_status_t st{};
  if (!ok_ || dds_get_publication_matched_status(request_writer_, &st) != DDS_RETCODE_OK) return 0;
  return static_cast<int>(st.current_count);
}

}  // namespace storey::drivers::go2
