#include "tools/sim/scene.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace storey::tools::sim {
namespace {

constexpr double kPi = 3.14159265358979323846;

// ---------------------------------------------------------------- YAML access with locations
struct Reader {
  std::string source;

  [[noreturn]] void fail(const YAML::Node& n, const std::string& key,
                         const std::string& why) const {
    std::ostringstream s;
    s << source;
    const YAML::Mark m = n.Mark();
    if (m.line >= 0) s << ":" << m.line + 1 << ":" << m.column + 1;
    s << ": " << key << ": " << why;
    throw std::runtime_error(s.str());
  }
  double num(const YAML::Node& n, const std::string& key) const {
    if (!n.IsScalar()) fail(n, key, "expected a number");
    try {
      const double v = n.as<double>();
      if (!std::isfinite(v)) fail(n, key, "must be finite");
      return v;
    } catch (const YAML::Exception&) {
      fail(n, key, "expected a number, got '" + n.Scalar() + "'");
    }
  }
  double num(const YAML::Node& map, const std::string& key, double def) const {
    const YAML::Node n = map[key];
    return n ? num(n, key) : def;
  }
  double req(const YAML::Node& map, const std::string& key) const {
    const YAML::Node n = map[key];
    if (!n) fail(map, key, "missing");
    return num(n, key);
  }
  double positive(const YAML::Node& map, const std::string& key, double def) const {
    const double v = num(map, key, def);
    if (!(v > 0.0)) fail(map[key] ? map[key] : map, key, "must be > 0");
    return v;
  }
  bool flag(const YAML::Node& map, const std::string& key, bool def) const {
    const YAML::Node n = map[key];
    if (!n) return def;
    try {
      return n.as<bool>();
    } catch (const YAML::Exception&) {
      fail(n, key, "expected true or false");
    }
  }
  std::string str(const YAML::Node& map, const std::string& key, const std::string& def) const {
    const YAML::Node n = map[key];
    if (!n) return def;
    if (!n.IsScalar()) fail(n, key, "expected a string");
    return n.Scalar();
  }
  std::vector<double> vec(const YAML::Node& n, const std::string& key, std::size_t size) const {
    if (!n.IsSequence() || n.size() != size)
      fail(n, key, "expected a list of " + std::to_string(size) + " numbers");
    std::vector<double> v;
    for (const auto& e : n) v.push_back(num(e, key));
    return v;
  }
  std::vector<double> req_vec(const YAML::Node& map, const std::string& key,
                              std::size_t size) const {
    const YAML::Node n = map[key];
    if (!n) fail(map, key, "missing");
    return vec(n, key, size);
  }
  // [x0, y0, x1, y1] with x0 < x1, y0 < y1.
  std::array<double, 4> rect(const YAML::Node& n, const std::string& key) const {
    const auto v = vec(n, key, 4);
    if (!(v[2] > v[0] && v[3] > v[1]))
      fail(n, key, "rectangle must be [x0, y0, x1, y1], x0<x1, y0<y1");
    return {v[0], v[1], v[2], v[3]};
  }
  std::vector<YAML::Node> list(const YAML::Node& map, const std::string& key) const {
    std::vector<YAML::Node> out;
    const YAML::Node n = map[key];
    if (!n) return out;
    if (!n.IsSequence()) fail(n, key, "expected a list");
    for (const auto& e : n) {
      if (!e.IsMap()) fail(e, key, "each entry must be a mapping");
      out.push_back(e);
    }
    return out;
  }
  void only(const YAML::Node& map, const std::string& what,
            std::initializer_list<const char*> keys) const {
    for (const auto& kv : map) {
      const std::string k = kv.first.as<std::string>();
      if (std::none_of(keys.begin(), keys.end(), [&](const char* a) { return k == a; }))
        fail(kv.first, what + "." + k, "unknown key");
    }
  }
};

using Rect = std::array<double, 4>;  // x0 y0 x1 y1

// Deterministic generator for the procedural maze (splitmix64: same maze on every platform).
struct SplitMix {
  uint64_t s;
  uint64_t next() {
    uint64_t z = (s += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }
};

// -------------------------------------------------------------------------- geometry builder
struct Builder {
  Mesh mesh;
  void box(double x0, double y0, double z0, double x1, double y1, double z1) {
    mesh.add_box(Eigen::Vector3f(float(x0), float(y0), float(z0)),
                 Eigen::Vector3f(float(x1), float(y1), float(z1)));
  }
  // Rectangle minus holes, as a set of boxes (grid decomposition, merged along x).
  void slab(const Rect& r, const std::vector<Rect>& holes, double z0, double z1) {
    std::vector<double> xs = {r[0], r[2]}, ys = {r[1], r[3]};
    for (const auto& h : holes) {
      xs.push_back(std::clamp(h[0], r[0], r[2]));
      xs.push_back(std::clamp(h[2], r[0], r[2]));
      ys.push_back(std::clamp(h[1], r[1], r[3]));
      ys.push_back(std::clamp(h[3], r[1], r[3]));
    }
    std::sort(xs.begin(), xs.end());
    xs.erase(std::unique(xs.begin(), xs.end()), xs.end());
    std::sort(ys.begin(), ys.end());
    ys.erase(std::unique(ys.begin(), ys.end()), ys.end());
    for (std::size_t j = 0; j + 1 < ys.size(); ++j) {
      const double cy = 0.5 * (ys[j] + ys[j + 1]);
      std::size_t i = 0;
      while (i + 1 < xs.size()) {
        auto solid = [&](std::size_t k) {
          const double cx = 0.5 * (xs[k] + xs[k + 1]);
          for (const auto& h : holes)
            if (cx > h[0] && cx < h[2] && cy > h[1] && cy < h[3]) return false;
          return true;
        };
        if (!solid(i)) {
          ++i;
          continue;
        }
        std::size_t k = i;
        while (k + 1 < xs.size() - 1 && solid(k + 1)) ++k;
        box(xs[i], ys[j], z0, xs[k + 1], ys[j + 1], z1);
        i = k + 1;
      }
    }
  }
};

struct Door {
  double at = 0.0;     // offset of the door's start along the wall from its first end [m]
  double width = 0.9;  // [m]
  bool open = true;
};

// A straight wall between two points with doors: open = gap (with a lintel), closed = panel.
void wall(Builder& b, double x0, double y0, double x1, double y1, double thickness, double z0,
          double z1, std::vector<Door> doors, double door_height) {
  const double len = std::hypot(x1 - x0, y1 - y0);
  if (len <= 1e-6) return;
  const double ux = (x1 - x0) / len, uy = (y1 - y0) / len;
  const double yaw = std::atan2(uy, ux);
  auto piece = [&](double s0, double s1, double za, double zb, double t) {
    if (s1 - s0 <= 1e-6 || zb - za <= 1e-6) return;
    const double sm = 0.5 * (s0 + s1);
    // Axis-aligned walls are extended by half the thickness so corners close.
    b.mesh.add_yawed_box(float(x0 + ux * sm), float(y0 + uy * sm), float(s1 - s0), float(t),
                         float(yaw), float(za), float(zb));
  };
  std::sort(doors.begin(), doors.end(), [](const Door& a, const Door& c) { return a.at < c.at; });
  const double ext = thickness / 2;
  double s = -ext;
  for (const auto& d : doors) {
    const double a = std::clamp(d.at, 0.0, len), e = std::clamp(d.at + d.width, 0.0, len);
    piece(s, a, z0, z1, thickness);
    if (d.open) {
      piece(a, e, std::min(z0 + door_height, z1), z1, thickness);  // lintel
    } else {
      piece(a, e, z0, z1, thickness * 0.6);  // door leaf inside the frame
    }
    s = std::max(s, e);
  }
  piece(s, len + ext, z0, z1, thickness);
}

struct FloorInfo {
  double elevation, height, slab, ceiling;  // ceiling = underside of the next slab
  Rect outline;
  std::vector<Rect> openings;
  YAML::Node node;
};

std::vector<Door> parse_doors(const Reader& r, const YAML::Node& owner, bool with_side,
                              std::vector<std::string>* sides) {
  std::vector<Door> out;
  for (const auto& d : r.list(owner, "doors")) {
    if (with_side)
      r.only(d, "door", {"side", "at", "width", "open"});
    else
      r.only(d, "door", {"at", "width", "open"});
    Door door;
    door.at = r.req(d, "at");
    door.width = r.positive(d, "width", 0.9);
    door.open = r.flag(d, "open", true);
    if (door.open && door.width < 0.8)
      r.fail(d, "door.width", "open doors must be >= 0.8 m for the robot");
    if (with_side) {
      const std::string side = r.str(d, "side", "");
      if (side != "north" && side != "south" && side != "east" && side != "west")
        r.fail(d, "door.side", "must be north, south, east or west");
      sides->push_back(side);
    }
    out.push_back(door);
  }
  return out;
}

// The four walls of a rectangle with doors on named sides (offsets from the west/south end).
void rect_walls(Builder& b, const Reader& r, const YAML::Node& owner, const Rect& rc, double t,
                double z0, double z1, double door_h) {
  std::vector<std::string> sides;
  const auto doors = parse_doors(r, owner, true, &sides);
  auto pick = [&](const char* side) {
    std::vector<Door> v;
    for (std::size_t i = 0; i < doors.size(); ++i)
      if (sides[i] == side) v.push_back(doors[i]);
    return v;
  };
  wall(b, rc[0], rc[1], rc[2], rc[1], t, z0, z1, pick("south"), door_h);
  wall(b, rc[0], rc[3], rc[2], rc[3], t, z0, z1, pick("north"), door_h);
  wall(b, rc[0], rc[1], rc[0], rc[3], t, z0, z1, pick("west"), door_h);
  wall(b, rc[2], rc[1], rc[2], rc[3], t, z0, z1, pick("east"), door_h);
}

// Stairs and ramps are laid out in a local frame: s along the first flight, l to its left.
struct Frame {
  double ox, oy, dx, dy;  // origin, unit direction (axis-aligned)
  Rect rect(double s0, double s1, double l0, double l1) const {
    const double ax = ox + dx * s0 - dy * l0, ay = oy + dy * s0 + dx * l0;
    const double bx = ox + dx * s1 - dy * l1, by = oy + dy * s1 + dx * l1;
    return {std::min(ax, bx), std::min(ay, by), std::max(ax, bx), std::max(ay, by)};
  }
};

Frame parse_frame(const Reader& r, const YAML::Node& n) {
  const auto at = r.req_vec(n, "at", 2);
  const std::string dir = r.str(n, "direction", "+x");
  Frame f{at[0], at[1], 0, 0};
  if (dir == "+x")
    f.dx = 1;
  else if (dir == "-x")
    f.dx = -1;
  else if (dir == "+y")
    f.dy = 1;
  else if (dir == "-y")
    f.dy = -1;
  else
    r.fail(n["direction"], "direction", "must be +x, -x, +y or -y");
  return f;
}

void rect_box(Builder& b, const Rect& rc, double z0, double z1) {
  b.box(rc[0], rc[1], z0, rc[2], rc[3], z1);
}

// Stairs from floor i to floor i+1 (rise <= max_rise, run; side walls that double as railings
// 1 m high on the upper floor; the upper slab gets the opening automatically).
void build_stairs(Builder& b, const Reader& r, const YAML::Node& n,
                  std::vector<FloorInfo>& floors) {
  r.only(n, "stairs",
         {"type", "floor", "at", "direction", "width", "run", "max_rise", "landing", "turn", "gap",
          "walls"});
  const int fi = static_cast<int>(r.req(n, "floor"));
  if (fi < 0 || fi + 1 >= static_cast<int>(floors.size()))
    r.fail(n["floor"], "stairs.floor", "must name a floor that has a floor above it");
  const std::string type = r.str(n, "type", "straight");
  const Frame f = parse_frame(r, n);
  const double w = r.positive(n, "width", 1.2);
  const double run = r.positive(n, "run", 0.29);
  const double max_rise = r.positive(n, "max_rise", 0.17);
  if (w < 1.0) r.fail(n["width"], "stairs.width", "must be >= 1.0 m for the robot");
  if (max_rise > 0.17 + 1e-9) r.fail(n["max_rise"], "stairs.max_rise", "must be <= 0.17 m");
  if (run < 0.25 || run > 0.35) r.fail(n["run"], "stairs.run", "must be within 0.25..0.35 m");
  const double landing = r.positive(n, "landing", w);
  const double gap = r.num(n, "gap", 0.2);
  const bool walls = r.flag(n, "walls", true);
  const std::string turn = r.str(n, "turn", "left");
  if (turn != "left" && turn != "right") r.fail(n["turn"], "stairs.turn", "must be left or right");
  const double sign = turn == "left" ? 1.0 : -1.0;
  FloorInfo& lo = floors[fi];
  FloorInfo& up = floors[fi + 1];
  const double z0 = lo.elevation, z1 = up.elevation, rise_total = z1 - z0;
  const int n_rise = static_cast<int>(std::ceil(rise_total / max_rise - 1e-9));
  const double rise = rise_total / n_rise;
  const double wt = 0.12, top = z1 + 1.0;  // wall thickness, railing top
  std::vector<Rect> holes;
  // l-interval helper for the turn side.
  auto lane = [&](double a, double c) { return sign > 0 ? std::pair{a, c} : std::pair{-c, -a}; };
  auto flight = [&](double s_start, double ds, int steps, double zb, double l0, double l1,
                    bool along_l) {
    // steps treads; tread k top at zb + (k+1)*rise; solid down to z0.
    for (int k = 0; k < steps; ++k) {
      const double a = s_start + ds * k * run, c = s_start + ds * (k + 1) * run;
      const Rect rc = along_l ? f.rect(l0, l1, std::min(a, c), std::max(a, c))
                              : f.rect(std::min(a, c), std::max(a, c), l0, l1);
      rect_box(b, rc, z0, zb + (k + 1) * rise);
    }
  };
  if (type == "straight") {
    const double L = (n_rise - 1) * run;
    flight(0.0, 1.0, n_rise - 1, z0, -w / 2, w / 2, false);
    holes.push_back(f.rect(0, L, -w / 2, w / 2));
    if (walls) {
      rect_box(b, f.rect(0, L, -w / 2 - wt, -w / 2), z0, top);
      rect_box(b, f.rect(0, L, w / 2, w / 2 + wt), z0, top);
      rect_box(b, f.rect(-wt, 0, -w / 2 - wt, w / 2 + wt), z1 - up.slab, top);  // upper railing
    }
  } else if (type == "U") {
    const int n1 = n_rise / 2, n2 = n_rise - n1;  // risers per flight (landing takes one)
    const double L1 = (n1 - 1) * run, zl = z0 + n1 * rise;
    const auto [a1, c1] = lane(-w / 2, w / 2);
    const auto [a2, c2] = lane(w / 2 + gap, 1.5 * w + gap);
    flight(0.0, 1.0, n1 - 1, z0, a1, c1, false);
    rect_box(b, f.rect(L1, L1 + landing, std::min(a1, a2), std::max(c1, c2)), z0, zl);
    // Flight 2 runs back from the landing; its treads start at s = L1.
    flight(L1, -1.0, n2 - 1, zl, a2, c2, false);
    const double L2end = L1 - (n2 - 1) * run;
    holes.push_back(f.rect(std::min(0.0, L2end), L1 + landing, std::min(a1, a2), std::max(c1, c2)));
    if (walls) {
      const auto [o1a, o1c] = lane(-w / 2 - wt, -w / 2);
      const auto [o2a, o2c] = lane(1.5 * w + gap, 1.5 * w + gap + wt);
      const auto [ma, mc] = lane(w / 2, w / 2 + gap);
      rect_box(b, f.rect(std::min(0.0, L2end), L1 + landing + wt, o1a, o1c), z0, top);
      rect_box(b, f.rect(std::min(0.0, L2end), L1 + landing + wt, o2a, o2c), z0, top);
      if (gap > 0.0) rect_box(b, f.rect(std::min(0.0, L2end), L1, ma, mc), z0, top);
      rect_box(b, f.rect(L1 + landing, L1 + landing + wt, std::min(o1a, o2a), std::max(o1c, o2c)),
               z0, top);
      rect_box(b, f.rect(-wt, 0, a1, c1), z1 - up.slab, top);
    }
  } else if (type == "L") {
    const int n1 = n_rise / 2, n2 = n_rise - n1;
    const double L1 = (n1 - 1) * run, zl = z0 + n1 * rise, L2 = (n2 - 1) * run;
    flight(0.0, 1.0, n1 - 1, z0, -w / 2, w / 2, false);
    rect_box(b, f.rect(L1, L1 + w, -w / 2, w / 2), z0, zl);
    // Flight 2 along +l (left) or -l (right), starting at the landing's side.
    const double l_start = sign * w / 2;
    flight(l_start, sign, n2 - 1, zl, L1, L1 + w, true);
    holes.push_back(f.rect(0, L1 + w, -w / 2, w / 2));
    const double l_end = l_start + sign * L2;
    holes.push_back(f.rect(L1, L1 + w, std::min(l_start, l_end), std::max(l_start, l_end)));
    if (walls) {
      const double outer = -sign * w / 2;  // side away from the turn
      rect_box(b,
               f.rect(0, L1 + w + wt, std::min(outer, outer - sign * wt),
                      std::max(outer, outer - sign * wt)),
               z0, top);
      rect_box(b,
               f.rect(0, L1, std::min(l_start, l_start + sign * wt),
                      std::max(l_start, l_start + sign * wt)),
               z0, top);
      rect_box(b, f.rect(L1 + w, L1 + w + wt, std::min(outer, l_end), std::max(outer, l_end)), z0,
               top);
      rect_box(b, f.rect(L1 - wt, L1, std::min(l_start, l_end), std::max(l_start, l_end)), z0, top);
      rect_box(b, f.rect(-wt, 0, -w / 2 - wt, w / 2 + wt), z1 - up.slab, top);
    }
  } else {
    r.fail(n["type"], "stairs.type", "must be straight, L or U");
  }
  up.openings.insert(up.openings.end(), holes.begin(), holes.end());
}

// Ramps from floor i to floor i+1 along axis-aligned segments [x0, y0, x1, y1] (centre lines);
// consecutive segments are joined by flat landings. Slope = rise / total segment length.
void build_ramp(Builder& b, const Reader& r, const YAML::Node& n, std::vector<FloorInfo>& floors) {
  r.only(n, "ramp", {"floor", "width", "segments", "slope_deg", "walls"});
  const int fi = static_cast<int>(r.req(n, "floor"));
  if (fi < 0 || fi + 1 >= static_cast<int>(floors.size()))
    r.fail(n["floor"], "ramp.floor", "must name a floor that has a floor above it");
  const double w = r.positive(n, "width", 1.5);
  if (w < 1.2) r.fail(n["width"], "ramp.width", "must be >= 1.2 m for the robot");
  const bool walls = r.flag(n, "walls", true);
  const YAML::Node segs = n["segments"];
  if (!segs || !segs.IsSequence() || segs.size() == 0)
    r.fail(n, "ramp.segments", "expected a list of [x0, y0, x1, y1]");
  std::vector<std::array<double, 4>> sv;
  double total = 0.0;
  for (const auto& s : segs) {
    const auto v = r.vec(s, "ramp.segments", 4);
    if (std::abs(v[0] - v[2]) > 1e-9 && std::abs(v[1] - v[3]) > 1e-9)
      r.fail(s, "ramp.segments", "segments must be axis-aligned");
    const double len = std::hypot(v[2] - v[0], v[3] - v[1]);
    if (len <= 0.0) r.fail(s, "ramp.segments", "zero-length segment");
    sv.push_back({v[0], v[1], v[2], v[3]});
    total += len;
  }
  FloorInfo& lo = floors[fi];
  FloorInfo& up = floors[fi + 1];
  const double z0 = lo.elevation, z1 = up.elevation;
  const double slope = std::atan2(z1 - z0, total) * 180.0 / kPi;
  if (n["slope_deg"]) {
    const double want = r.num(n["slope_deg"], "ramp.slope_deg");
    if (std::abs(want - slope) > 0.25)
      r.fail(n["slope_deg"], "ramp.slope_deg",
             "segments give " + std::to_string(slope) + " deg; total length for " +
                 std::to_string(want) + " deg is " +
                 std::to_string((z1 - z0) / std::tan(want * kPi / 180.0)) + " m");
  }
  if (slope > 30.0) r.fail(n, "ramp", "slope above 30 deg");
  const double wt = 0.12, top = z1 + 1.0;
  double z = z0;
  for (std::size_t i = 0; i < sv.size(); ++i) {
    const auto& s = sv[i];
    const double len = std::hypot(s[2] - s[0], s[3] - s[1]);
    const double ux = (s[2] - s[0]) / len, uy = (s[3] - s[1]) / len;
    const double za = z, zb = z + (z1 - z0) * len / total;
    const double px = -uy * w / 2, py = ux * w / 2;  // half-width to the left
    const float fz0 = float(z0);
    // bottom corners counter-clockwise from above: start-right, end-right, end-left, start-left
    const Eigen::Vector3f c0(float(s[0] - px), float(s[1] - py), fz0);
    const Eigen::Vector3f c1(float(s[2] - px), float(s[3] - py), fz0);
    const Eigen::Vector3f c2(float(s[2] + px), float(s[3] + py), fz0);
    const Eigen::Vector3f c3(float(s[0] + px), float(s[1] + py), fz0);
    auto topv = [](Eigen::Vector3f c, double zz) {
      c.z() = float(zz);
      return c;
    };
    if (zb > z0 + 1e-6) {
      b.mesh.add_hexahedron({c0, c1, c2, c3, topv(c0, std::max(za, z0 + 1e-3)), topv(c1, zb),
                             topv(c2, zb), topv(c3, std::max(za, z0 + 1e-3))});
    }
    const Rect rc = {std::min(c0.x(), c2.x()), std::min(c0.y(), c2.y()), std::max(c0.x(), c2.x()),
                     std::max(c0.y(), c2.y())};
    up.openings.push_back(rc);
    if (walls) {
      // Side walls along both edges (railings on the upper floor).
      wall(b, s[0] - px * (1 + 2 * wt / w), s[1] - py * (1 + 2 * wt / w),
           s[2] - px * (1 + 2 * wt / w), s[3] - py * (1 + 2 * wt / w), wt * 2, z0, top, {}, 0.0);
      wall(b, s[0] + px * (1 + 2 * wt / w), s[1] + py * (1 + 2 * wt / w),
           s[2] + px * (1 + 2 * wt / w), s[3] + py * (1 + 2 * wt / w), wt * 2, z0, top, {}, 0.0);
      if (i == 0)  // railing across the bottom end on the upper floor
        rect_box(b,
                 {std::min(c0.x(), c3.x()) - float(wt), std::min(c0.y(), c3.y()) - float(wt),
                  std::max(c0.x(), c3.x()) + float(wt), std::max(c0.y(), c3.y()) + float(wt)},
                 z1 - up.slab, top);
    }
    z = zb;
    if (i + 1 < sv.size()) {
      const auto& nx = sv[i + 1];
      // The landing starts where this segment ends and reaches w beyond it, and covers the
      // next segment's start the same way, so no sloped part lies under it.
      const double nl = std::hypot(nx[2] - nx[0], nx[3] - nx[1]);
      const double vx = (nx[2] - nx[0]) / nl, vy = (nx[3] - nx[1]) / nl;
      const double ptsx[4] = {s[2], s[2] + ux * w, nx[0], nx[0] - vx * w};
      const double ptsy[4] = {s[3], s[3] + uy * w, nx[1], nx[1] - vy * w};
      Rect land = {1e18, 1e18, -1e18, -1e18};
      for (int q = 0; q < 4; ++q) {
        const bool along_x = q < 2 ? std::abs(ux) > 0.5 : std::abs(vx) > 0.5;
        const double lx = along_x ? 0.0 : w / 2, ly = along_x ? w / 2 : 0.0;
        land = {std::min(land[0], ptsx[q] - lx), std::min(land[1], ptsy[q] - ly),
                std::max(land[2], ptsx[q] + lx), std::max(land[3], ptsy[q] + ly)};
      }
      rect_box(b, land, z0, z);
      up.openings.push_back(land);
      if (walls) {
        // Railings round the landing, with gaps where the two segments join it.
        auto gap_on = [&](const std::array<double, 4>& sg, bool at_end, double x0, double y0,
                          double x1, double y1, std::vector<Door>& gaps) {
          const double ex = at_end ? sg[2] : sg[0], ey = at_end ? sg[3] : sg[1];
          const bool horizontal = std::abs(y1 - y0) < 1e-9;
          const double dist = horizontal ? std::abs(ey - y0) : std::abs(ex - x0);
          const bool vertical_seg = std::abs(sg[0] - sg[2]) < 1e-9;
          if (dist > wt + 1e-6 || horizontal != vertical_seg) return;
          const double c = horizontal ? ex - x0 : ey - y0;
          gaps.push_back({c - w / 2 - wt, w + 2 * wt, true});
        };
        const double L0 = land[0] - wt, L1 = land[1] - wt, L2 = land[2] + wt, L3 = land[3] + wt;
        const std::array<std::array<double, 4>, 4> sides = {
            {{L0, L1, L2, L1}, {L0, L3, L2, L3}, {L0, L1, L0, L3}, {L2, L1, L2, L3}}};
        for (const auto& sd : sides) {
          std::vector<Door> gaps;
          gap_on(s, true, sd[0], sd[1], sd[2], sd[3], gaps);
          gap_on(nx, false, sd[0], sd[1], sd[2], sd[3], gaps);
          wall(b, sd[0], sd[1], sd[2], sd[3], wt * 2, z0, top, gaps, top - z0 + 1.0);
        }
      }
    }
  }
}

// Maze of cells with walls on cell borders: depth-first perfect maze plus `loops` fraction of
// extra removed walls (intersections). Cells whose centre lies in a `clear` rectangle lose all
// their walls (space for ramps, stairs, the start).
void build_maze(Builder& b, const Reader& r, const YAML::Node& n, double z0, double z1) {
  r.only(n, "maze", {"rect", "cell", "seed", "loops", "thickness", "clear"});
  const Rect rc = r.rect(n["rect"], "maze.rect");
  const double cell = r.positive(n, "cell", 2.5);
  const double t = r.positive(n, "thickness", 0.15);
  if (cell - t < 1.2) r.fail(n["cell"], "maze.cell", "corridors must be >= 1.2 m wide");
  const double loops = r.num(n, "loops", 0.15);
  const int nx = static_cast<int>(std::floor((rc[2] - rc[0]) / cell + 1e-9));
  const int ny = static_cast<int>(std::floor((rc[3] - rc[1]) / cell + 1e-9));
  if (nx < 2 || ny < 2) r.fail(n["rect"], "maze.rect", "too small for two cells");
  std::vector<Rect> clear;
  if (n["clear"]) {
    if (!n["clear"].IsSequence()) r.fail(n["clear"], "maze.clear", "expected a list of rectangles");
    for (const auto& c : n["clear"]) clear.push_back(r.rect(c, "maze.clear"));
  }
  SplitMix rng{static_cast<uint64_t>(r.num(n, "seed", 1.0))};
  // east[i][j]: wall between (i,j) and (i+1,j); north[i][j]: between (i,j) and (i,j+1).
  std::vector<char> east(nx * ny, 1), north(nx * ny, 1), seen(nx * ny, 0);
  auto id = [&](int i, int j) { return j * nx + i; };
  std::vector<int> stack = {0};
  seen[0] = 1;
  while (!stack.empty()) {
    const int c = stack.back();
    const int i = c % nx, j = c / nx;
    int cand[4], k = 0;
    if (i + 1 < nx && !seen[id(i + 1, j)]) cand[k++] = 0;
    if (i > 0 && !seen[id(i - 1, j)]) cand[k++] = 1;
    if (j + 1 < ny && !seen[id(i, j + 1)]) cand[k++] = 2;
    if (j > 0 && !seen[id(i, j - 1)]) cand[k++] = 3;
    if (k == 0) {
      stack.pop_back();
      continue;
    }
    const int d = cand[rng.next() % k];
    int ni = i, nj = j;
    if (d == 0) east[id(i, j)] = 0, ni = i + 1;
    if (d == 1) east[id(i - 1, j)] = 0, ni = i - 1;
    if (d == 2) north[id(i, j)] = 0, nj = j + 1;
    if (d == 3) north[id(i, j - 1)] = 0, nj = j - 1;
    seen[id(ni, nj)] = 1;
    stack.push_back(id(ni, nj));
  }
  auto in_clear = [&](int i, int j) {
    const double cx = rc[0] + (i + 0.5) * cell, cy = rc[1] + (j + 0.5) * cell;
    for (const auto& c : clear)
      if (cx > c[0] && cx < c[2] && cy > c[1] && cy < c[3]) return true;
    return false;
  };
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      if (east[id(i, j)] && rng.uniform() < loops) east[id(i, j)] = 0;
      if (north[id(i, j)] && rng.uniform() < loops) north[id(i, j)] = 0;
    }
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const double x = rc[0] + (i + 1) * cell, y = rc[1] + (j + 1) * cell;
      if (i + 1 < nx && east[id(i, j)] && !in_clear(i, j) && !in_clear(i + 1, j))
        b.box(x - t / 2, y - cell - t / 2, z0, x + t / 2, y + t / 2, z1);
      if (j + 1 < ny && north[id(i, j)] && !in_clear(i, j) && !in_clear(i, j + 1))
        b.box(x - cell - t / 2, y - t / 2, z0, x + t / 2, y + t / 2, z1);
    }
}

void build_obstacle(Builder& b, const Reader& r, const YAML::Node& o, double z0, double z1) {
  r.only(o, "obstacle", {"type", "at", "size", "height", "yaw"});
  const std::string type = r.str(o, "type", "");
  const auto at = r.req_vec(o, "at", 2);
  const double yaw = r.num(o, "yaw", 0.0) * kPi / 180.0;
  if (type == "table") {
    const auto sz = r.req_vec(o, "size", 2);
    const double h = r.positive(o, "height", 0.75);
    const double top = 0.04, leg = 0.06;
    b.mesh.add_yawed_box(float(at[0]), float(at[1]), float(sz[0]), float(sz[1]), float(yaw),
                         float(z0 + h - top), float(z0 + h));
    const double c = std::cos(yaw), s = std::sin(yaw);
    for (int k = 0; k < 4; ++k) {
      const double lx = (k & 1 ? 1 : -1) * (sz[0] / 2 - leg),
                   ly = (k & 2 ? 1 : -1) * (sz[1] / 2 - leg);
      b.mesh.add_yawed_box(float(at[0] + c * lx - s * ly), float(at[1] + s * lx + c * ly),
                           float(leg), float(leg), float(yaw), float(z0), float(z0 + h - top));
    }
  } else if (type == "pillar") {
    const auto sz =
        o["size"] ? r.vec(o["size"], "obstacle.size", 2) : std::vector<double>{0.4, 0.4};
    b.mesh.add_yawed_box(float(at[0]), float(at[1]), float(sz[0]), float(sz[1]), float(yaw),
                         float(z0), float(z1));
  } else if (type == "box") {
    const auto sz = r.req_vec(o, "size", 3);
    b.mesh.add_yawed_box(float(at[0]), float(at[1]), float(sz[0]), float(sz[1]), float(yaw),
                         float(z0), float(z0 + sz[2]));
  } else {
    r.fail(o, "obstacle.type", "must be table, pillar or box");
  }
}

}  // namespace

Scene build_scene_from_yaml(const std::string& text, const std::string& source) {
  const Reader r{source};
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::ParserException& e) {
    throw std::runtime_error(source + ":" + std::to_string(e.mark.line + 1) + ":" +
                             std::to_string(e.mark.column + 1) + ": YAML syntax: " + e.msg);
  }
  if (!root.IsMap()) r.fail(root, "(root)", "expected a mapping");
  r.only(root, "scene",
         {"name", "start", "wall_thickness", "door_height", "floors", "stairs", "ramps", "mesh",
          "scale", "up"});
  Scene scene;
  scene.name = r.str(root, "name", source);
  if (root["start"]) {
    const auto s = r.vec(root["start"], "start", 4);
    scene.start = StartPose{s[0], s[1], s[2], s[3] * kPi / 180.0};
  }
  if (root["mesh"]) {  // a mesh file world with a start pose
    MeshLoadOptions mo;
    mo.scale = r.positive(root, "scale", 1.0);
    const std::string up = r.str(root, "up", "z");
    if (up != "z" && up != "y") r.fail(root["up"], "up", "must be z or y");
    mo.up = up == "y" ? UpAxis::y : UpAxis::z;
    std::string path = r.str(root, "mesh", "");
    const auto slash = source.find_last_of('/');
    if (!path.empty() && path[0] != '/' && slash != std::string::npos)
      path = source.substr(0, slash + 1) + path;
    scene.mesh = load_mesh(path, mo);
    return scene;
  }
  const double def_t = r.positive(root, "wall_thickness", 0.15);
  const double door_h = r.positive(root, "door_height", 2.1);
  const YAML::Node fl = root["floors"];
  if (!fl || !fl.IsSequence() || fl.size() == 0)
    r.fail(root, "floors", "expected a non-empty list");
  std::vector<FloorInfo> floors;
  for (const auto& f : fl) {
    if (!f.IsMap()) r.fail(f, "floors", "each floor must be a mapping");
    r.only(f, "floor",
           {"elevation", "height", "slab_thickness", "outline", "openings", "outer_walls", "walls",
            "rooms", "room_rows", "maze", "obstacles"});
    FloorInfo info;
    info.elevation = r.req(f, "elevation");
    info.height = r.positive(f, "height", 3.0);
    info.slab = r.positive(f, "slab_thickness", 0.2);
    if (!f["outline"]) r.fail(f, "floor.outline", "missing");
    info.outline = r.rect(f["outline"], "floor.outline");
    for (const auto& o : f["openings"] ? f["openings"] : YAML::Node())
      info.openings.push_back(r.rect(o, "floor.openings"));
    if (!floors.empty() && info.elevation <= floors.back().elevation + 2.0)
      r.fail(f["elevation"], "floor.elevation", "floors must be listed bottom-up, >= 2 m apart");
    info.node.reset(f);
    floors.push_back(info);
    scene.design_floors.push_back(info.elevation);
  }
  for (std::size_t i = 0; i < floors.size(); ++i) {
    const bool last = i + 1 == floors.size();
    floors[i].ceiling = last ? floors[i].elevation + floors[i].height
                             : floors[i + 1].elevation - floors[i + 1].slab;
    if (!last && std::abs(floors[i].elevation + floors[i].height - floors[i + 1].elevation) > 1e-6)
      r.fail(floors[i + 1].node["elevation"], "floor.elevation",
             "must equal the previous floor's elevation + height");
  }
  Builder b;
  for (const auto& s : r.list(root, "stairs")) build_stairs(b, r, s, floors);
  for (const auto& s : r.list(root, "ramps")) build_ramp(b, r, s, floors);
  for (std::size_t i = 0; i < floors.size(); ++i) {
    const FloorInfo& fi = floors[i];
    const YAML::Node& f = fi.node;
    const double z0 = fi.elevation, z1 = fi.ceiling;
    b.slab(fi.outline, fi.openings, fi.elevation - fi.slab, fi.elevation);
    if (i + 1 == floors.size()) b.slab(fi.outline, {}, z1, z1 + fi.slab);  // roof
    if (f["outer_walls"]) {
      const YAML::Node ow = f["outer_walls"];
      r.only(ow, "outer_walls", {"thickness", "doors"});
      const double t = r.positive(ow, "thickness", 0.25);
      const Rect& o = fi.outline;
      // Centred on the outline inset by half the thickness, so the slab edge is the outer face.
      rect_walls(b, r, ow, {o[0] + t / 2, o[1] + t / 2, o[2] - t / 2, o[3] - t / 2}, t, z0, z1,
                 door_h);
    }
    for (const auto& w : r.list(f, "walls")) {
      r.only(w, "wall", {"from", "to", "thickness", "height", "doors"});
      const auto a = r.req_vec(w, "from", 2), c = r.req_vec(w, "to", 2);
      const double h = r.num(w, "height", z1 - z0);
      wall(b, a[0], a[1], c[0], c[1], r.positive(w, "thickness", def_t), z0, std::min(z0 + h, z1),
           parse_doors(r, w, false, nullptr), door_h);
    }
    for (const auto& rm : r.list(f, "rooms")) {
      r.only(rm, "room", {"rect", "doors", "thickness"});
      if (!rm["rect"]) r.fail(rm, "room.rect", "missing");
      rect_walls(b, r, rm, r.rect(rm["rect"], "room.rect"), r.positive(rm, "thickness", def_t), z0,
                 z1, door_h);
    }
    for (const auto& row : r.list(f, "room_rows")) {
      // `count` equal rooms side by side along `axis`, one door each on `door_side` (centred).
      r.only(row, "room_row",
             {"rect", "count", "axis", "door_side", "door_width", "closed", "thickness"});
      const Rect rc = r.rect(row["rect"], "room_row.rect");
      const int cnt = static_cast<int>(r.req(row, "count"));
      if (cnt < 1 || cnt > 100) r.fail(row["count"], "room_row.count", "must be 1..100");
      const std::string axis = r.str(row, "axis", "x");
      const std::string side = r.str(row, "door_side", "north");
      const double dw = r.positive(row, "door_width", 0.9);
      const double t = r.positive(row, "thickness", def_t);
      std::vector<int> closed;
      if (row["closed"])
        for (const auto& c : row["closed"])
          closed.push_back(static_cast<int>(r.num(c, "room_row.closed")));
      for (int k = 0; k < cnt; ++k) {
        Rect cell = rc;
        if (axis == "x") {
          const double wdt = (rc[2] - rc[0]) / cnt;
          cell[0] = rc[0] + k * wdt, cell[2] = cell[0] + wdt;
        } else {
          const double wdt = (rc[3] - rc[1]) / cnt;
          cell[1] = rc[1] + k * wdt, cell[3] = cell[1] + wdt;
        }
        const bool ns = side == "north" || side == "south";
        const double len = ns ? cell[2] - cell[0] : cell[3] - cell[1];
        YAML::Node door_owner;
        YAML::Node d;
        d["side"] = side;
        d["at"] = (len - dw) / 2;
        d["width"] = dw;
        d["open"] = std::find(closed.begin(), closed.end(), k) == closed.end();
        door_owner["doors"].push_back(d);
        rect_walls(b, r, door_owner, cell, t, z0, z1, door_h);
      }
    }
    if (f["maze"]) build_maze(b, r, f["maze"], z0, z1);
    for (const auto& o : r.list(f, "obstacles")) build_obstacle(b, r, o, z0, z1);
  }
  scene.mesh = std::move(b.mesh);
  if (!scene.mesh.valid()) throw std::runtime_error(source + ": generated mesh is not valid");
  return scene;
}

Scene load_scene(const std::string& name_or_file, const MeshLoadOptions& mesh_options) {
  for (const auto& s : builtin_scenes())
    if (name_or_file == s.name) return build_scene_from_yaml(s.yaml, std::string(s.name) + ".yaml");
  auto ends = [&](const char* ext) {
    const std::string e(ext);
    return name_or_file.size() > e.size() &&
           name_or_file.compare(name_or_file.size() - e.size(), e.size(), e) == 0;
  };
  std::ifstream in(name_or_file);
  if (!in) {
    std::string names;
    for (const auto& s : builtin_scenes()) names += std::string(names.empty() ? "" : ", ") + s.name;
    throw std::runtime_error("scene '" + name_or_file + "' is neither a built-in scene (" + names +
                             ") nor a readable file");
  }
  if (ends(".yaml") || ends(".yml")) {
    std::stringstream ss;
    ss << in.rdbuf();
    return build_scene_from_yaml(ss.str(), name_or_file);
  }
  Scene scene;
  scene.name = name_or_file;
  scene.mesh = load_mesh(name_or_file, mesh_options);
  return scene;
}

}  // namespace storey::tools::sim
