// Go2 sport service request ids and the JSON parameter of Move, as used on
// rt/api/sport/request (unitree_sdk2 include/unitree/robot/go2/sport/sport_api.hpp; Move's
// parameter {"x": vx, "y": vy, "z": vyaw} from sport_client). Dependency-free, no allocation.
#pragma once

#include <cstddef>
#include <cstdint>

#include "drivers/go2/robot_messages.hpp"

namespace storey::drivers::go2 {

inline constexpr int64_t kApiDamp = 1001;
inline constexpr int64_t kApiBalanceStand = 1002;
inline constexpr int64_t kApiStopMove = 1003;
inline constexpr int64_t kApiStandUp = 1004;
inline constexpr int64_t kApiStandDown = 1005;
inline constexpr int64_t kApiRecoveryStand = 1006;
inline constexpr int64_t kApiMove = 1008;

int64_t api_id_for(ModeRequest m);
// Inverse of api_id_for; false for ids that are not a ModeRequest.
bool mode_for_api_id(int64_t api_id, ModeRequest& out);

// Writes {"x": vx, "y": vy, "z": vyaw} (shortest round-trip floats) NUL-terminated into buf.
// Returns the length, or 0 if cap is too small (64 bytes always suffice).
size_t format_move_parameter(float vx, float vy, float vyaw, char* buf, size_t cap);

// Parses Move's JSON parameter: keys x, y, z in any order, any whitespace; other keys ignored.
// False on malformed JSON, a missing key or a non-finite number.
bool parse_move_parameter(const char* json, size_t len, float& vx, float& vy, float& vyaw);

}  // namespace storey::drivers::go2
