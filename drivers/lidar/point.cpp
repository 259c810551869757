#include "drivers/lidar/point.hpp"

namespace storey::drivers::lidar {

const char* to_string(DropReason r) {
  switch (r) {
    case DropReason::none:
      return "none";
    case DropReason::short_packet:
      return "short";
    case DropReason::bad_size:
      return "bad_size";
    case DropReason::bad_flag:
      return "bad_flag";
    case DropReason::bad_azimuth:
      return "bad_azimuth";
    case DropReason::bad_return_mode:
      return "bad_return_mode";
    case DropReason::bad_dual_pair:
      return "bad_dual_pair";
    case DropReason::bad_version:
      return "bad_version";
    case DropReason::bad_length:
      return "bad_length";
    case DropReason::unknown_type:
      return "unknown_type";
    case DropReason::bad_crc:
      return "bad_crc";
    case DropReason::buffer_too_small:
      return "buffer_too_small";
    case DropReason::wrong_source:
      return "wrong_source";
    case DropReason::queue_full:
      return "queue_full";
    case DropReason::count_:
      break;
  }
  return "unknown";
}

}  // namespace storey::drivers::lidar
