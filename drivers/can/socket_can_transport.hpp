// SocketCAN raw socket (AF_CAN, CAN_RAW): id filters (CAN_RAW_FILTER), FD frames
// (CAN_RAW_FD_FRAMES), error frames (CAN_RAW_ERR_FILTER) with bus-off recovery, and the kernel's
// drop count (SO_RXQ_OVFL). Needs a kernel with CAN (vcan for tests:
// `ip link add dev vcan0 type vcan && ip link set up vcan0`); where AF_CAN is missing, ok() is
// false and errno_value() is EAFNOSUPPORT.
#pragma once

#include <array>
#include <cstdint>
#include <string>

#include "drivers/can/can_transport.hpp"

namespace storey::drivers::can {

struct SocketCanOptions {
  std::string interface = "can0";
  bool fd_frames = true;  // enable CAN_RAW_FD_FRAMES (classic frames still work)
  bool receive_own = false;
  // While bus-off, the socket is re-created every this often until the controller restarts
  // (the kernel restarts it itself when `ip link set can0 type can restart-ms 100` is set).
  int64_t reopen_period_ns = 200'000'000;
};

class SocketCanTransport final : public CanTransport {
 public:
  explicit SocketCanTransport(const SocketCanOptions& options);
  ~SocketCanTransport() override;

  bool ok() const override { return fd_ >= 0; }
  const char* error() const override { return error_.c_str(); }
  int errno_value() const { return errno_; }
  bool set_filters(const CanFilter* filters, int n) override;
  CanIoStatus send(const CanFrame& f) override;
  CanIoStatus receive(CanFrame& f) override;
  CanTransportStats stats() const override { return stats_; }
  bool bus_off() const { return bus_off_; }

  static constexpr int kMaxFilters = 16;

 private:
  bool open_socket();
  void close_socket();
  void handle_error_frame(uint32_t id, const uint8_t* data);
  static int64_t now_ns();

  SocketCanOptions options_;
  int fd_ = -1;
  int errno_ = 0;
  std::string error_;
  std::array<CanFilter, kMaxFilters> filters_{};
  int n_filters_ = 0;
  bool bus_off_ = false;
  int64_t bus_off_since_ns_ = 0;
  uint32_t last_ovfl_ = 0;
  CanTransportStats stats_;
};

}  // namespace storey::drivers::can
