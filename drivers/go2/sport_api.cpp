#include "drivers/go2/sport_api.hpp"

#include <charconv>
#include <cmath>
#include <cstring>

namespace storey::drivers::go2 {

int64_t api_id_for(ModeRequest m) {
  switch (m) {
    case ModeRequest::stop:
      return kApiStopMove;
    case ModeRequest::balance_stand:
      return kApiBalanceStand;
    case ModeRequest::stand_up:
      return kApiStandUp;
    case ModeRequest::stand_down:
      return kApiStandDown;
    case ModeRequest::damp:
      return kApiDamp;
  }
  return kApiStopMove;
}

bool mode_for_api_id(int64_t api_id, ModeRequest& out) {
  switch (api_id) {
    case kApiStopMove:
      out = ModeRequest::stop;
      return true;
    case kApiBalanceStand:
      out = ModeRequest::balance_stand;
      return true;
    case kApiStandUp:
      out = ModeRequest::stand_up;
      return true;
    case kApiStandDown:
      out = ModeRequest::stand_down;
      return true;
    case kApiDamp:
      out = ModeRequest::damp;
      return true;
    default:
      return false;
  }
}

size_t format_move_parameter(float vx, float vy, float vyaw, char* buf, size_t cap) {
  char* p = buf;
  char* const end = buf + cap;
  auto put = [&](const char* s) {
    const size_t n = std::strlen(s);
    if (static_cast<size_t>(end - p) <= n) return false;
    std::memcpy(p, s, n);
    p += n;
    return true;
  };
  auto num = [&](float v) {
    const auto r = std::to_chars(p, end, v);
    if (r.ec != std::errc()) return false;
    p = r.ptr;
    return true;
  };
  if (!(put("{\"x\": ") && num(vx) && put(", \"y\": ") && num(vy) && put(", \"z\": ") &&
        num(vyaw) && put("}"))) {
    return 0;
  }
  if (p >= end) return 0;
  *p = '\0';
  return static_cast<size_t>(p - buf);
}

bool parse_move_parameter(const char* json, size_t len, float& vx, float& vy, float& vyaw) {
  const char* p = json;
  const char* const end = json + len;
  auto skip_ws = [&] {
    while (p < end && (*p == ' ' || *p == '\t' || *p == '\n' || *p == '\r')) ++p;
  };
  skip_ws();
  if (p >= end || *p != '{') return false;
  ++p;
  bool got[3] = {false, false, false};
  float val[3] = {0, 0, 0};
  for (;;) {
    skip_ws();
    if (p < end && *p == '}') break;
    if (p >= end || *p != '"') return false;
    const char* key = ++p;
    while (p < end && *p != '"') ++p;
    if (p >= end) return false;
    const size_t key_len = static_cast<size_t>(p - key);
    ++p;
    skip_ws();
    if (p >= end || *p != ':') return false;
    ++p;
    skip_ws();
    double v = 0;
    const auto r = std::from_chars(p, end, v);
    if (r.ec != std::errc()) return false;  // only numeric values are expected here
    p = r.ptr;
    if (key_len == 1 && (key[0] == 'x' || key[0] == 'y' || key[0] == 'z')) {
      const int i = key[0] - 'x';
      got[i] = true;
      val[i] = static_cast<float>(v);
    }
    skip_ws();
    if (p < end && *p == ',') {
      ++p;
      continue;
    }
    if (p < end && *p == '}') break;
    return false;
  }
  if (!(got[0] && got[1] && got[2])) return false;
  for (float f : val) {
    if (!std::isfinite(f)) return false;
  }
  vx = val[0];
  vy = val[1];
  vyaw = val[2];
  return true;
}

}  // namespace storey::drivers::go2
