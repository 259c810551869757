#include "tools/sim/ground_truth.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <deque>
#include <map>
#include <stdexcept>
#include <tuple>

namespace storey::tools::sim {

namespace {
constexpr double kBias = 1e-4;  // in voxels; see VoxelKey
int vk(double v, double res) {
  return static_cast<int>(std::floor(v / res + kBias));
}
}  // namespace

VoxelKey voxel_key(const Eigen::Vector3d& p, double res) {
  return {vk(p.x(), res), vk(p.y(), res), vk(p.z(), res)};
}

GroundTruth::GroundTruth(const Mesh& mesh, const std::optional<StartPose>& start,
                         const GroundTruthOptions& options)
    : opt_(options) {
  if (mesh.empty()) throw std::runtime_error("ground truth: empty mesh");
  if (!(opt_.resolution > 0.0)) throw std::runtime_error("ground truth: resolution must be > 0");
  if (!(opt_.collision_radius >= 0.0 && opt_.collision_radius <= 2.0))
    throw std::runtime_error("ground truth: collision_radius must be in [0, 2] m (got " +
                             std::to_string(opt_.collision_radius) + ")");
  bounds_ = mesh.bounds();
  const double r = opt_.resolution;
  const int clear = static_cast<int>(std::ceil(opt_.body_clearance / r - 1e-9));
  min_ = voxel_key(bounds_.min.cast<double>(), r);
  min_.x -= 1, min_.y -= 1, min_.z -= 1;
  const VoxelKey mx = voxel_key(bounds_.max.cast<double>(), r);
  nx_ = mx.x - min_.x + 2;
  ny_ = mx.y - min_.y + 2;
  nz_ = mx.z - min_.z + 2 + clear;
  const double cells = double(nx_) * ny_ * nz_;
  if (cells > 2e9) throw std::runtime_error("ground truth: world too large for a dense grid");
  grid_.assign(static_cast<std::size_t>(cells), 0);
  SampleHeights heights;
  voxelise(mesh, heights);
  find_support();
  find_clearance(heights);
  start_voxel_ = find_start(start);
  flood_fill();
  find_floors();
}

// Dense surface sampling: every triangle is sampled on a grid with spacing <= res/2 along the two
// edges that meet at its largest angle, so every voxel the surface crosses gets a sample (up to
// slivers at voxel corners, irrelevant for coverage with 1-voxel tolerance).
void GroundTruth::voxelise(const Mesh& mesh, SampleHeights& heights) {
  const double r = opt_.resolution, h = 0.5 * r;
  heights.lo.assign(grid_.size(), 255);
  heights.hi.assign(grid_.size(), 0);
  auto mark = [&](const Eigen::Vector3d& p, uint8_t f) {
    const VoxelKey k = voxel_key(p, r);
    if (!inside(k)) return;
    const std::size_t i = index(k);
    grid_[i] |= f;
    const long q = std::clamp(std::lround((p.z() / r - k.z) * 255.0), 0L, 255L);
    heights.lo[i] = std::min(heights.lo[i], static_cast<uint8_t>(q));
    heights.hi[i] = std::max(heights.hi[i], static_cast<uint8_t>(q));
  };
  const double min_nz = std::cos(opt_.max_slope_deg * M_PI / 180.0);
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& tri = mesh.triangles[t];
    Eigen::Vector3d v[3] = {mesh.vertices[tri[0]].cast<double>(),
                            mesh.vertices[tri[1]].cast<double>(),
                            mesh.vertices[tri[2]].cast<double>()};
    const Eigen::Vector3d nrm = (v[1] - v[0]).cross(v[2] - v[0]);
    if (nrm.norm() <= 0.0) continue;
    const uint8_t f = kOccupied | (nrm.z() / nrm.norm() >= min_nz ? kWalkable : 0);
    // Vertex opposite the longest edge has the largest angle.
    int a = 0;
    double best = -1;
    for (int i = 0; i < 3; ++i) {
      const double len = (v[(i + 1) % 3] - v[(i + 2) % 3]).squaredNorm();
      if (len > best) best = len, a = i;
    }
    const Eigen::Vector3d o = v[a], e1 = v[(a + 1) % 3] - o, e2 = v[(a + 2) % 3] - o;
    const int n1 = std::max(1, static_cast<int>(std::ceil(e1.norm() / h)));
    const int n2 = std::max(1, static_cast<int>(std::ceil(e2.norm() / h)));
    for (int i = 0; i <= n1; ++i) {
      const double u = double(i) / n1;
      const int jmax = static_cast<int>(std::floor((1.0 - u) * n2 + 1e-9));
      for (int j = 0; j <= jmax; ++j) {
        mark(o + u * e1 + (double(j) / n2) * e2, f);
      }
      // The far edge point for this row, so the edge opposite `o` is sampled too.
      mark(o + u * e1 + (1.0 - u) * e2, f);
    }
  }
  occupied_count_ = 0;
  for (auto c : grid_) occupied_count_ += (c & kOccupied) ? 1 : 0;
}

void GroundTruth::find_support() {
  const int clear = static_cast<int>(std::ceil(opt_.body_clearance / opt_.resolution - 1e-9));
  const std::size_t layer = std::size_t(nx_) * ny_;
  for (int z = 0; z + clear < nz_; ++z)
    for (std::size_t xy = 0; xy < layer; ++xy) {
      uint8_t& c = grid_[z * layer + xy];
      if ((c & (kOccupied | kWalkable)) != (kOccupied | kWalkable)) continue;
      bool free = true;
      for (int d = 1; d <= clear && free; ++d) free = !(grid_[(z + d) * layer + xy] & kOccupied);
      if (free) c |= kSupport;
    }
}

// Horizontal clearance, mirroring R_col of the map (core/map/terrain_analysis.cpp, paper III-A
// Eq. 3): support voxel v is blocked when a voxel in the disc of ceil(collision_radius / res)
// voxels around its column, from v's level up to the body clearance + 1 voxel, holds surface
// geometry higher than step_height and no higher than body_clearance above v's support surface.
// The map compares one surface height per voxel (its points' mean); the truth uses the sample
// range of the voxel, so a wall is caught where its geometry enters that band, and the next stair
// tread (0.167 m up, below the step height) is not an obstacle.
void GroundTruth::find_clearance(const SampleHeights& h) {
  const double r = opt_.resolution;
  const int rc = static_cast<int>(std::ceil(opt_.collision_radius / r - 1e-9));
  const int hc = static_cast<int>(std::ceil(opt_.body_clearance / r - 1e-9));
  const double step = opt_.step_height / r, clear = opt_.body_clearance / r;  // in voxels
  const std::size_t layer = std::size_t(nx_) * ny_;
  for (int z = 0; z < nz_; ++z)
    for (int y = 0; y < ny_; ++y)
      for (int x = 0; x < nx_; ++x) {
        const std::size_t i = z * layer + std::size_t(y) * nx_ + x;
        if (!(grid_[i] & kSupport)) continue;
        const double hv = z + h.hi[i] / 255.0;  // support surface [voxels]
        bool hit = false;
        for (int dy = -rc; dy <= rc && !hit; ++dy)
          for (int dx = -rc; dx <= rc && !hit; ++dx) {
            if (dx * dx + dy * dy > rc * rc) continue;
            const int cx = x + dx, cy = y + dy;
            if (cx < 0 || cy < 0 || cx >= nx_ || cy >= ny_) continue;
            for (int dz = 0; dz <= hc + 1 && z + dz < nz_ && !hit; ++dz) {
              const std::size_t j = (z + dz) * layer + std::size_t(cy) * nx_ + cx;
              if (!(grid_[j] & kOccupied)) continue;
              const double lo = z + dz + h.lo[j] / 255.0, hi = z + dz + h.hi[j] / 255.0;
              hit = hi > hv + step && lo <= hv + clear;
            }
          }
        if (!hit) grid_[i] |= kClear;
      }
}

VoxelKey GroundTruth::find_start(const std::optional<StartPose>& start) {
  const double r = opt_.resolution;
  const std::size_t layer = std::size_t(nx_) * ny_;
  if (start) {
    start_ = *start;
    const VoxelKey c = voxel_key({start->x, start->y, start->z}, r);
    // Nearest support voxel with clearance in height (within 0.5 m) in the column, then in
    // growing rings up to 1 m (the map seeds C_reach likewise, map.seed_search_radius_m).
    const int rings = static_cast<int>(std::ceil(1.0 / r - 1e-9));
    for (int rad = 0; rad <= rings; ++rad) {
      std::optional<VoxelKey> best;
      double best_d = 1e9;
      for (int dy = -rad; dy <= rad; ++dy)
        for (int dx = -rad; dx <= rad; ++dx) {
          if (std::max(std::abs(dx), std::abs(dy)) != rad) continue;
          for (int dz = -5; dz <= 5; ++dz) {
            const VoxelKey k{c.x + dx, c.y + dy, c.z + dz};
            if (!clear(k)) continue;
            const double d = std::abs(dz) + 0.1 * (std::abs(dx) + std::abs(dy));
            if (d < best_d) best_d = d, best = k;
          }
        }
      if (best) return *best;
    }
    throw std::runtime_error(
        "ground truth: no walkable support with clearance within 1 m of the start (" +
        std::to_string(start->x) + ", " + std::to_string(start->y) + ", " +
        std::to_string(start->z) + ")");
  }
  // No start given: lowest height level with floor_min_area of support; its voxel nearest the
  // level's centroid whose 5x5 neighbourhood is all support at the same height.
  for (int z = 0; z < nz_; ++z) {
    std::size_t n = 0;
    double sx = 0, sy = 0;
    for (std::size_t xy = 0; xy < layer; ++xy)
      if (grid_[z * layer + xy] & kSupport) ++n, sx += double(xy % nx_), sy += double(xy / nx_);
    if (n * r * r < opt_.floor_min_area) continue;
    sx /= double(n), sy /= double(n);
    std::optional<VoxelKey> best;
    double best_d = 1e18;
    for (std::size_t xy = 0; xy < layer; ++xy) {
      const int x = int(xy % nx_), y = int(xy / nx_);
      const VoxelKey k{min_.x + x, min_.y + y, min_.z + z};
      if (!clear(k)) continue;
      bool flat = true;
      for (int dy = -2; dy <= 2 && flat; ++dy)
        for (int dx = -2; dx <= 2 && flat; ++dx) flat = support({k.x + dx, k.y + dy, k.z});
      const double d = (x - sx) * (x - sx) + (y - sy) * (y - sy);
      if (flat && d < best_d) best_d = d, best = k;
    }
    if (best) {
      start_ = StartPose{(best->x + 0.5) * r, (best->y + 0.5) * r, best->z * r, 0.0};
      return *best;
    }
  }
  throw std::runtime_error("ground truth: no floor-sized walkable support in the mesh");
}

// Region growing over support voxels with clearance (paper III-A: reachable set C_reach from
// the robot's support voxel over traversable voxels): 8-neighbours horizontally, height change
// <= step height.
void GroundTruth::flood_fill() {
  const int max_dz = static_cast<int>(std::ceil(opt_.step_height / opt_.resolution - 1e-9));
  std::deque<VoxelKey> open = {start_voxel_};
  grid_[index(start_voxel_)] |= kReachable;
  reachable_.clear();
  while (!open.empty()) {
    const VoxelKey k = open.front();
    open.pop_front();
    reachable_.push_back(k);
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        if (dx == 0 && dy == 0) continue;
        for (int dz = -max_dz; dz <= max_dz; ++dz) {
          const VoxelKey n{k.x + dx, k.y + dy, k.z + dz};
          if (!inside(n)) continue;
          uint8_t& c = grid_[index(n)];
          if ((c & (kSupport | kClear)) == (kSupport | kClear) && !(c & kReachable)) {
            c |= kReachable;
            open.push_back(n);
          }
        }
      }
  }
  std::sort(reachable_.begin(), reachable_.end(), [](const VoxelKey& a, const VoxelKey& b) {
    return std::tie(a.z, a.y, a.x) < std::tie(b.z, b.y, b.x);
  });
}

// Floors: histogram of reachable support heights weighted by area; levels holding at least
// floor_min_area are floor candidates; candidates within 0.3 m merge (keeping the larger).
void GroundTruth::find_floors() {
  std::map<int, std::size_t> hist;
  for (const auto& k : reachable_) ++hist[k.z];
  const double a = opt_.resolution * opt_.resolution;
  std::vector<std::pair<int, std::size_t>> peaks;
  const int merge = std::max(1, static_cast<int>(std::lround(0.3 / opt_.resolution)));
  for (const auto& [z, n] : hist) {
    if (n * a < opt_.floor_min_area) continue;
    if (!peaks.empty() && z - peaks.back().first <= merge) {
      if (n > peaks.back().second) peaks.back() = {z, n};
      continue;
    }
    peaks.emplace_back(z, n);
  }
  floors_.clear();
  for (const auto& p : peaks) floors_.push_back({p.first * opt_.resolution, 0.0, 0});
  for (const auto& k : reachable_) {
    const int f = floor_of(k);
    if (f >= 0) ++floors_[f].voxels;
  }
  for (auto& f : floors_) f.traversable_area_m2 = double(f.voxels) * a;
}

int GroundTruth::floor_of(const VoxelKey& k) const {
  int best = -1;
  double bd = 1e18;
  for (std::size_t i = 0; i < floors_.size(); ++i) {
    const double d = std::abs(k.z * opt_.resolution - floors_[i].z_m);
    if (d < bd) bd = d, best = static_cast<int>(i);
  }
  return best;
}

double GroundTruth::traversable_volume_m3() const {
  return double(reachable_.size()) * std::pow(opt_.resolution, 3);
}
double GroundTruth::occupied_volume_m3() const {
  return double(occupied_count_) * std::pow(opt_.resolution, 3);
}

std::string GroundTruth::describe_json(const std::string& scene_name) const {
  std::string s;
  char buf[512];
  std::string name;
  for (char c : scene_name) {
    if (c == '"' || c == '\\') name += '\\';
    if (static_cast<unsigned char>(c) >= 0x20) name += c;
  }
  std::snprintf(buf, sizeof buf,
                "{\n  \"scene\": \"%s\",\n  \"resolution_m\": %.3f,\n"
                "  \"bounding_box\": {\"min\": [%.3f, %.3f, %.3f], \"max\": [%.3f, %.3f, %.3f]},\n"
                "  \"start\": [%.3f, %.3f, %.3f, %.4f],\n  \"floors\": [",
                name.c_str(), opt_.resolution, bounds_.min.x(), bounds_.min.y(), bounds_.min.z(),
                bounds_.max.x(), bounds_.max.y(), bounds_.max.z(), start_.x, start_.y, start_.z,
                start_.yaw);
  s += buf;
  for (std::size_t i = 0; i < floors_.size(); ++i) {
    std::snprintf(buf, sizeof buf, "%s\n    {\"z_m\": %.2f, \"traversable_area_m2\": %.2f}",
                  i ? "," : "", floors_[i].z_m, floors_[i].traversable_area_m2);
    s += buf;
  }
  std::snprintf(buf, sizeof buf,
                "\n  ],\n  \"traversable_volume_m3\": %.3f,\n  \"occupied_volume_m3\": %.3f\n}\n",
                traversable_volume_m3(), occupied_volume_m3());
  s += buf;
  return s;
}

}  // namespace storey::tools::sim
