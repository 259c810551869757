#pragma once
// Stamped body poses from the robot link, for deskewing LiDAR points (paper Sec. III-A assumes
// motion-compensated scans): the control task pushes each new robot state, the ingest task reads
// the ring and interpolates a pose at every point's time. Fixed size, no allocation, no lock.
//
// Contract: one writer thread calls push(); any number of readers call snapshot(). Each slot is
// a seqlock whose sequence encodes which push filled it (2*i+2 once push i is in, odd while
// being written), so a reader skips a slot that is mid-write or was overwritten meanwhile.
#include <algorithm>
#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>

#include <Eigen/Geometry>

namespace storey::firmware {

// Body pose at a time on the firmware clock (CLOCK_MONOTONIC ns): position [m] of the body
// origin in the odometry frame and orientation (unit quaternion).
struct StampedPose {
  std::int64_t t_ns = 0;
  Eigen::Vector3d p_m = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
};

class PoseHistory {
 public:
  static constexpr std::size_t kCapacity = 256;  // 2.5 s at the Go2's 100 Hz state rate

  // Writer only. Stamps must increase; an older or equal stamp is refused (counted).
  bool push(const StampedPose& s) noexcept {
    if (last_t_ns_ != kNone && s.t_ns <= last_t_ns_) {
      refused_.store(refused_.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
      return false;
    }
    last_t_ns_ = s.t_ns;
    const std::uint64_t i = head_.load(std::memory_order_relaxed);
    Slot& slot = slots_[i % kCapacity];
    slot.seq.store(2 * i + 1, std::memory_order_relaxed);
    std::atomic_thread_fence(std::memory_order_release);
    slot.t.store(s.t_ns, std::memory_order_relaxed);
    const double v[7] = {s.p_m.x(), s.p_m.y(), s.p_m.z(), s.q.w(), s.q.x(), s.q.y(), s.q.z()};
    for (int k = 0; k < 7; ++k) slot.v[k].store(v[k], std::memory_order_relaxed);
    slot.seq.store(2 * i + 2, std::memory_order_release);
    head_.store(i + 1, std::memory_order_release);
    return true;
  }

  // Any thread: copies the consistent samples, oldest first, into `out`; returns how many.
  std::size_t snapshot(std::array<StampedPose, kCapacity>& out) const noexcept {
    const std::uint64_t n = head_.load(std::memory_order_acquire);
    const std::uint64_t first = n > kCapacity ? n - kCapacity : 0;
    std::size_t m = 0;
    for (std::uint64_t i = first; i < n; ++i) {
      const Slot& slot = slots_[i % kCapacity];
      if (slot.seq.load(std::memory_order_acquire) != 2 * i + 2) continue;
      StampedPose s;
      s.t_ns = slot.t.load(std::memory_order_relaxed);
      double v[7];
      for (int k = 0; k < 7; ++k) v[k] = slot.v[k].load(std::memory_order_relaxed);
      std::atomic_thread_fence(std::memory_order_acquire);
      if (slot.seq.load(std::memory_order_relaxed) != 2 * i + 2) continue;  // overwritten
      s.p_m = {v[0], v[1], v[2]};
      s.q = Eigen::Quaterniond(v[3], v[4], v[5], v[6]);
      out[m++] = s;
    }
    return m;
  }

  std::uint64_t pushed() const noexcept { return head_.load(std::memory_order_acquire); }
  std::uint64_t refused() const noexcept { return refused_.load(std::memory_order_relaxed); }

  // Pose at t from samples sorted by time (a snapshot): linear in position, slerp in rotation
  // between the two samples around t. Past the newest sample it extrapolates with the last two
  // samples' motion for at most `max_extrapolation_ns` (robot states arrive a few ms after the
  // LiDAR's newest points); before the oldest, or without samples: false. `hint` (in/out) is the
  // index of the last bracket used: queries that advance in time cost O(1).
  static bool interpolate(const StampedPose* s, std::size_t n, std::int64_t t_ns,
                          std::int64_t max_extrapolation_ns, StampedPose& out,
                          std::size_t* hint = nullptr) noexcept {
    if (n == 0 || t_ns < s[0].t_ns) return false;
    if (t_ns >= s[n - 1].t_ns) {
      if (t_ns - s[n - 1].t_ns > max_extrapolation_ns) return false;
      if (n == 1 || t_ns == s[n - 1].t_ns) {
        out = s[n - 1];
        out.t_ns = t_ns;
        return true;
      }
      return blend(s[n - 2], s[n - 1], t_ns, out);
    }
    std::size_t i = hint ? std::min(*hint, n - 2) : 0;
    if (s[i].t_ns > t_ns) i = 0;  // went back in time: search from the start
    while (i + 1 < n && s[i + 1].t_ns <= t_ns) ++i;
    if (hint) *hint = i;
    return blend(s[i], s[i + 1], t_ns, out);
  }

 private:
  static bool blend(const StampedPose& a, const StampedPose& b, std::int64_t t_ns,
                    StampedPose& out) noexcept {
    const double u = double(t_ns - a.t_ns) / double(b.t_ns - a.t_ns);
    out.t_ns = t_ns;
    out.p_m = a.p_m + u * (b.p_m - a.p_m);
    if (u <= 1.0) {
      out.q = a.q.slerp(u, b.q);
    } else {  // extrapolation: apply the a->b rotation (u - 1) more times, as an angle-axis
      const Eigen::AngleAxisd d(b.q * a.q.inverse());
      out.q = Eigen::AngleAxisd(d.angle() * (u - 1.0), d.axis()) * b.q;
    }
    out.q.normalize();
    return true;
  }

  static constexpr std::int64_t kNone = INT64_MIN;
  struct alignas(64) Slot {
    std::atomic<std::uint64_t> seq{0};
    std::atomic<std::int64_t> t{0};
    std::atomic<double> v[7] = {};
  };
  std::array<Slot, kCapacity> slots_{};
  alignas(64) std::atomic<std::uint64_t> head_{0};
  std::atomic<std::uint64_t> refused_{0};
  std::int64_t last_t_ns_ = kNone;  // writer only
};

}  // namespace storey::firmware
