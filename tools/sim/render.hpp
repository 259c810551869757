// Pictures of a scene and its ground truth (PNG via libpng): a top-down view per floor and a side
// view (x-z). Views map world coordinates to pixels, so maps, graphs and trajectories can be
// drawn over them later (point / line / polyline in colour).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "tools/sim/ground_truth.hpp"

namespace storey::tools::sim {

struct Rgb {
  uint8_t r = 0, g = 0, b = 0;
};

class Image {
 public:
  Image(int width, int height, Rgb fill = {255, 255, 255});
  int width() const { return w_; }
  int height() const { return h_; }
  void set(int x, int y, Rgb c) {
    if (x >= 0 && y >= 0 && x < w_ && y < h_) px_[std::size_t(y) * w_ + x] = c;
  }
  Rgb get(int x, int y) const { return px_[std::size_t(y) * w_ + x]; }
  void line(int x0, int y0, int x1, int y1, Rgb c);  // Bresenham
  void disc(int x, int y, int radius, Rgb c);
  // Throws std::runtime_error naming the file on failure.
  void save_png(const std::string& path) const;

 private:
  int w_, h_;
  std::vector<Rgb> px_;
};

// World -> pixel mapping with overlay helpers. kind: top-down (x right, y up) or side (x right,
// z up).
class View {
 public:
  enum class Kind { top_down, side };
  View(Kind kind, double x0, double v0, double x1, double v1, double metres_per_pixel);
  Image& image() { return img_; }
  const Image& image() const { return img_; }
  Eigen::Vector2i pixel(const Eigen::Vector3d& p) const;
  void point(const Eigen::Vector3d& p, Rgb c, int radius = 1);
  void line(const Eigen::Vector3d& a, const Eigen::Vector3d& b, Rgb c);
  void polyline(const std::vector<Eigen::Vector3d>& pts, Rgb c);
  void save_png(const std::string& path) const { img_.save_png(path); }

 private:
  Kind kind_;
  double x0_, v1_, mpp_;
  Image img_;
};

// Top-down view of floor `floor` (index into gt.floors()): walls (occupied 0.3-1.8 m above the
// floor) dark, reachable support of this floor light green, stairs/ramps light blue, unreachable
// support (table tops) orange, 2 pixels per voxel by default.
View render_floor(const GroundTruth& gt, int floor, int pixels_per_voxel = 2);
// Side view (x-z): occupied voxels shaded by how many lie along y, reachable support green.
View render_side(const GroundTruth& gt, int pixels_per_voxel = 2);
// Writes DIR/floor_<i>.png for every floor and DIR/side.png (creates DIR). Returns the paths.
std::vector<std::string> render_scene(const GroundTruth& gt, const std::string& dir);

}  // namespace storey::tools::sim
