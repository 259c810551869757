#include "core/plan/floor_tracker.hpp"

#include <algorithm>
#include <cmath>

namespace storey::core::plan {

bool FloorTracker::update(const Eigen::Vector3d& foot, double t) {
  const double z = foot.z();
  if (!foot.allFinite() || !std::isfinite(t)) {
    ++bad_input_;
    return false;
  }
  if (current_ < 0) {
    floors_.push_back({0, z, t, false, 1.0, 0, z});
    current_ = 0;
    changed_to_new_ = true;
    return true;
  }
  const double zc = floors_[size_t(current_)].z_m;
  if (std::abs(z - zc) <= opt_.floor_change_dz_m) {
    candidate_ = false;  // back on (or never left) the current floor
    return false;
  }
  if (!candidate_ || std::abs(z - cand_z_) > opt_.stable_band_m) {
    candidate_ = true;  // still moving (stairs, ramp): restart the stability window
    cand_z_ = z;
    cand_since_ = t;
    cand_xy_ = foot.head<2>();
    return false;
  }
  if (t - cand_since_ < opt_.stable_s) return false;
  if ((foot.head<2>() - cand_xy_).norm() < opt_.stable_travel_m) return false;
  candidate_ = false;
  int32_t best = -1;
  for (const Floor& f : floors_)
    if (std::abs(f.z_m - z) <= 0.5 * opt_.floor_change_dz_m &&
        (best < 0 || std::abs(f.z_m - z) < std::abs(floors_[size_t(best)].z_m - z)))
      best = f.id;
  changed_to_new_ = best < 0;
  if (best < 0) {
    best = int32_t(floors_.size());
    floors_.push_back({best, z, t, false, 1.0, 0, z});
  }
  current_ = best;
  return true;
}

int32_t FloorTracker::floor_of(double z) const {
  int32_t best = -1;
  double bd = opt_.node_band_m;
  for (const Floor& f : floors_) {
    const double d = std::abs(f.z_m - z);
    if (d <= bd) {
      bd = d;
      best = f.id;
    }
  }
  return best;
}

void FloorTracker::refine(std::span<const float> node_z) {
  // The mode is taken only over nodes within max_refine_shift_m of where the robot stood on the
  // floor; with fewer than min_mode_nodes there the floor keeps its height.
  const double w = opt_.max_refine_shift_m;
  const int bins = std::max(1, int(std::ceil(2 * w / opt_.mode_bin_m)));
  for (Floor& f : floors_) {
    hist_.assign(size_t(bins), 0);
    const double lo = f.anchor_z_m - w;
    int n = 0, near = 0;
    for (float zf : node_z) {
      const double zz = zf;
      if (floor_of(zz) != f.id) continue;
      ++n;
      if (std::abs(zz - f.anchor_z_m) > w) continue;
      ++hist_[size_t(std::clamp(int((zz - lo) / opt_.mode_bin_m), 0, bins - 1))];
      ++near;
    }
    f.nodes = n;
    if (near < opt_.min_mode_nodes) continue;
    const int mode = int(std::max_element(hist_.begin(), hist_.end()) - hist_.begin());
    // Mean of the node heights in the mode bin and its two neighbours.
    double sum = 0;
    int cnt = 0;
    for (float zf : node_z) {
      const double zz = zf;
      if (floor_of(zz) != f.id || std::abs(zz - f.anchor_z_m) > w) continue;
      const int b = std::clamp(int((zz - lo) / opt_.mode_bin_m), 0, bins - 1);
      if (std::abs(b - mode) <= 1) {
        sum += zz;
        ++cnt;
      }
    }
    if (cnt > 0) f.z_m = sum / cnt;
  }
}

int32_t FloorTracker::choose_reference(int32_t target) const {
  if (target < 0 || size_t(target) >= floors_.size()) return -1;
  const double zt = floors_[size_t(target)].z_m;
  int32_t below = -1, above = -1;
  for (const Floor& f : floors_) {
    if (f.id == target) continue;
    if (f.z_m < zt && (below < 0 || f.z_m > floors_[size_t(below)].z_m)) below = f.id;
    if (f.z_m > zt && (above < 0 || f.z_m < floors_[size_t(above)].z_m)) above = f.id;
  }
  auto better = [&](int32_t a, int32_t b) {  // is a a better reference than b?
    if (b < 0) return a >= 0;
    if (a < 0) return false;
    const Floor &fa = floors_[size_t(a)], &fb = floors_[size_t(b)];
    if (fa.explored != fb.explored) return fa.explored;
    if (fa.open_ratio != fb.open_ratio) return fa.open_ratio < fb.open_ratio;
    if (fa.nodes != fb.nodes) return fa.nodes > fb.nodes;
    return a < b;
  };
  return better(above, below) ? above : below;
}

}  // namespace storey::core::plan
