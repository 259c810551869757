#pragma once
// Analytic worlds for map tests and benchmarks: oriented boxes, a ray caster against them and
// LiDAR-like scan generators (seeded RNG, so every run sees the same points).
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include <Eigen/Geometry>

namespace storey::test {

struct Box {
  Eigen::Vector3f centre;
  Eigen::Vector3f half;                               // half extents in the box frame [m]
  Eigen::Matrix3f rot = Eigen::Matrix3f::Identity();  // box frame -> world
};

inline Box aabb(Eigen::Vector3f lo, Eigen::Vector3f hi) {
  return Box{(lo + hi) * 0.5f, (hi - lo) * 0.5f};
}

// A slab of thickness t whose top surface is a plane rising along +x at `angle` [rad], starting
// at (x0, y0..y1, z0) for a horizontal run `run` [m].
inline Box ramp(float x0, float y0, float y1, float z0, float run, float angle, float t = 0.2f) {
  const float len = run / std::cos(angle);
  Box b;
  b.rot = Eigen::AngleAxisf(-angle, Eigen::Vector3f::UnitY()).toRotationMatrix();
  b.half = Eigen::Vector3f(len * 0.5f, (y1 - y0) * 0.5f, t * 0.5f);
  // Top-surface centre, then down by t/2 along the box's z axis.
  const Eigen::Vector3f top(x0 + run * 0.5f, (y0 + y1) * 0.5f, z0 + run * 0.5f * std::tan(angle));
  b.centre = top - b.rot.col(2) * (t * 0.5f);
  return b;
}

struct World {
  std::vector<Box> boxes;

  void add(const Box& b) { boxes.push_back(b); }
  // Stairs rising along +x from (x0, y0..y1, z0): n steps of rise/tread, solid underneath.
  void stairs(float x0, float y0, float y1, float z0, int n, float rise, float tread) {
    for (int i = 0; i < n; ++i)
      add(aabb({x0 + i * tread, y0, z0 - 0.2f}, {x0 + (i + 1) * tread, y1, z0 + (i + 1) * rise}));
  }

  // Distance along the unit direction d from o to the first surface, or +inf.
  float cast(const Eigen::Vector3f& o, const Eigen::Vector3f& d, float max_t) const {
    float best = max_t;
    for (const Box& b : boxes) {
      const Eigen::Vector3f lo = b.rot.transpose() * (o - b.centre);
      const Eigen::Vector3f ld = b.rot.transpose() * d;
      float t0 = 0, t1 = best;
      bool miss = false;
      for (int a = 0; a < 3 && !miss; ++a) {
        if (std::abs(ld[a]) < 1e-12f) {
          if (std::abs(lo[a]) > b.half[a]) miss = true;
          continue;
        }
        float ta = (-b.half[a] - lo[a]) / ld[a], tb = (b.half[a] - lo[a]) / ld[a];
        if (ta > tb) std::swap(ta, tb);
        t0 = std::max(t0, ta);
        t1 = std::min(t1, tb);
        if (t0 > t1) miss = true;
      }
      if (!miss && t0 > 1e-6f && t0 < best) best = t0;
    }
    return best < max_t ? best : std::numeric_limits<float>::infinity();
  }
};

// Dense random-direction scanner (a stand-in for a LiDAR with good coverage): n rays, uniform in
// azimuth, elevation uniform in [el_min, el_max], range noise sigma.
inline std::vector<Eigen::Vector3f> scan_dense(const World& w, const Eigen::Vector3f& o, int n,
                                               uint32_t seed, float el_min = -1.2f,
                                               float el_max = 0.6f, float max_range = 30.f,
                                               float sigma = 0.003f) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> az(0.f, 2.f * float(M_PI)), el(el_min, el_max);
  std::normal_distribution<float> noise(0.f, sigma);
  std::vector<Eigen::Vector3f> pts;
  pts.reserve(n);
  for (int i = 0; i < n; ++i) {
    const float a = az(rng), e = el(rng);
    const Eigen::Vector3f d(std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e));
    const float t = w.cast(o, d, max_range);
    if (std::isfinite(t)) pts.push_back(o + d * (t + noise(rng)));
  }
  return pts;
}

// Velodyne VLP-16: 16 rings from -15 to +15 deg, 1800 azimuth steps (0.2 deg) = 28,800 rays.
inline std::vector<Eigen::Vector3f> scan_vlp16(const World& w, const Eigen::Vector3f& o, float yaw0,
                                               uint32_t seed, float max_range = 100.f) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> noise(0.f, 0.01f);
  std::vector<Eigen::Vector3f> pts;
  pts.reserve(28800);
  for (int k = 0; k < 1800; ++k)
    for (int ring = 0; ring < 16; ++ring) {
      const float a = yaw0 + float(k) * 2.f * float(M_PI) / 1800.f;
      const float e = (-15.f + 2.f * ring) * float(M_PI) / 180.f;
      const Eigen::Vector3f d(std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e));
      const float t = w.cast(o, d, max_range);
      if (std::isfinite(t)) pts.push_back(o + d * (t + noise(rng)));
    }
  return pts;
}

// Livox Mid-360 (100 ms frame): ~20,000 rays, 360 deg azimuth, elevation -7..52 deg, a
// rosette-like non-repetitive pattern (golden-angle azimuth, pseudo-random elevation).
inline std::vector<Eigen::Vector3f> scan_mid360(const World& w, const Eigen::Vector3f& o,
                                                uint32_t frame, float max_range = 70.f) {
  std::mt19937 rng(frame * 7919u + 1);
  std::uniform_real_distribution<float> el(-7.f * float(M_PI) / 180.f, 52.f * float(M_PI) / 180.f);
  std::normal_distribution<float> noise(0.f, 0.02f);
  std::vector<Eigen::Vector3f> pts;
  pts.reserve(20000);
  const float golden = float(M_PI) * (3.f - std::sqrt(5.f));
  for (int i = 0; i < 20000; ++i) {
    const float a = golden * float(i + frame * 20000u);
    const float e = el(rng);
    const Eigen::Vector3f d(std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e));
    const float t = w.cast(o, d, max_range);
    if (std::isfinite(t)) pts.push_back(o + d * (t + noise(rng)));
  }
  return pts;
}

// A building-like box world: 40 x 20 m floor, 3 m storey, outer walls, interior walls with
// doors, a few pillars and a ceiling (for the insertion benchmarks).
inline World office_box_world() {
  World w;
  w.add(aabb({-20, -10, -0.2f}, {20, 10, 0.0f}));  // floor
  w.add(aabb({-20, -10, 3.0f}, {20, 10, 3.2f}));   // ceiling
  w.add(aabb({-20.2f, -10, 0}, {-20, 10, 3}));     // outer walls
  w.add(aabb({20, -10, 0}, {20.2f, 10, 3}));
  w.add(aabb({-20, -10.2f, 0}, {20, -10, 3}));
  w.add(aabb({-20, 10, 0}, {20, 10.2f, 3}));
  for (int i = -3; i <= 3; ++i) {  // rooms along both sides of a corridor, doors 1 m wide
    const float x = i * 5.0f;
    w.add(aabb({x - 0.05f, -10, 0}, {x + 0.05f, -2, 3}));
    w.add(aabb({x - 0.05f, 2, 0}, {x + 0.05f, 10, 3}));
    w.add(aabb({x - 2.5f, -2.05f, 0}, {x + 1.0f, -1.95f, 3}));
    w.add(aabb({x + 2.0f, -2.05f, 0}, {x + 2.5f, -1.95f, 3}));
    w.add(aabb({x - 2.5f, 1.95f, 0}, {x + 1.0f, 2.05f, 3}));
    w.add(aabb({x + 2.0f, 1.95f, 0}, {x + 2.5f, 2.05f, 3}));
    w.add(aabb({x + 1.2f, 5.8f, 0}, {x + 1.6f, 6.2f, 3}));        // pillar
    w.add(aabb({x - 1.5f, -7.0f, 0}, {x - 0.5f, -6.0f, 0.75f}));  // table block
  }
  return w;
}

}  // namespace storey::test
