#include "tools/sim/render.hpp"

#include <png.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <stdexcept>

namespace storey::tools::sim {

Image::Image(int width, int height, Rgb fill)
    : w_(std::max(1, width)), h_(std::max(1, height)), px_(std::size_t(w_) * h_, fill) {}

void Image::line(int x0, int y0, int x1, int y1, Rgb c) {
  const int dx = std::abs(x1 - x0), dy = -std::abs(y1 - y0);
  const int sx = x0 < x1 ? 1 : -1, sy = y0 < y1 ? 1 : -1;
  int err = dx + dy;
  for (int guard = 0; guard < 1 << 20; ++guard) {
    set(x0, y0, c);
    if (x0 == x1 && y0 == y1) break;
    const int e2 = 2 * err;
    if (e2 >= dy) err += dy, x0 += sx;
    if (e2 <= dx) err += dx, y0 += sy;
  }
}

void Image::disc(int x, int y, int radius, Rgb c) {
  for (int dy = -radius; dy <= radius; ++dy)
    for (int dx = -radius; dx <= radius; ++dx)
      if (dx * dx + dy * dy <= radius * radius) set(x + dx, y + dy, c);
}

void Image::save_png(const std::string& path) const {
  std::unique_ptr<FILE, int (*)(FILE*)> f(std::fopen(path.c_str(), "wb"), &std::fclose);
  if (!f) throw std::runtime_error(path + ": cannot open for writing");
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!png || !info) {
    png_destroy_write_struct(&png, &info);
    throw std::runtime_error(path + ": libpng init failed");
  }
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    throw std::runtime_error(path + ": PNG write failed");
  }
  png_init_io(png, f.get());
  png_set_IHDR(png, info, w_, h_, 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  std::vector<uint8_t> row(std::size_t(w_) * 3);
  for (int y = 0; y < h_; ++y) {
    for (int x = 0; x < w_; ++x) {
      const Rgb c = px_[std::size_t(y) * w_ + x];
      row[3 * x] = c.r, row[3 * x + 1] = c.g, row[3 * x + 2] = c.b;
    }
    png_write_row(png, row.data());
  }
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
}

View::View(Kind kind, double x0, double v0, double x1, double v1, double mpp)
    : kind_(kind),
      x0_(x0),
      v1_(v1),
      mpp_(mpp),
      img_(int(std::ceil((x1 - x0) / mpp - 1e-6)), int(std::ceil((v1 - v0) / mpp - 1e-6))) {}

Eigen::Vector2i View::pixel(const Eigen::Vector3d& p) const {
  const double v = kind_ == Kind::top_down ? p.y() : p.z();
  return {int(std::floor((p.x() - x0_) / mpp_)), int(std::floor((v1_ - v) / mpp_))};
}
void View::point(const Eigen::Vector3d& p, Rgb c, int radius) {
  const auto q = pixel(p);
  img_.disc(q.x(), q.y(), radius, c);
}
void View::line(const Eigen::Vector3d& a, const Eigen::Vector3d& b, Rgb c) {
  const auto p = pixel(a), q = pixel(b);
  img_.line(p.x(), p.y(), q.x(), q.y(), c);
}
void View::polyline(const std::vector<Eigen::Vector3d>& pts, Rgb c) {
  for (std::size_t i = 1; i < pts.size(); ++i) line(pts[i - 1], pts[i], c);
}

namespace {
// Voxel (column i, row j counted from the view's lower-left voxel) -> ppv x ppv pixel block.
void fill_voxel(View& v, int i, int j, int ppv, Rgb c) {
  const int y0 = v.image().height() - (j + 1) * ppv;
  for (int dy = 0; dy < ppv; ++dy)
    for (int dx = 0; dx < ppv; ++dx) v.image().set(i * ppv + dx, y0 + dy, c);
}
}  // namespace

View render_floor(const GroundTruth& gt, int floor, int ppv) {
  const double r = gt.resolution();
  const VoxelKey m = gt.min_key();
  const Eigen::Vector3i d = gt.dims();
  View view(View::Kind::top_down, m.x * r, m.y * r, (m.x + d.x()) * r, (m.y + d.y()) * r, r / ppv);
  const double fz = gt.floors().at(floor).z_m;
  const double next =
      std::size_t(floor + 1) < gt.floors().size() ? gt.floors()[floor + 1].z_m : 1e9;
  const double prev = floor > 0 ? gt.floors()[floor - 1].z_m : -1e9;
  const Rgb wall{60, 60, 70}, trav{170, 225, 160}, trans{150, 190, 240}, table{240, 170, 80},
      empty{245, 245, 245};
  for (int y = 0; y < d.y(); ++y)
    for (int x = 0; x < d.x(); ++x) {
      Rgb c = empty;
      int prio = 0;
      for (int z = 0; z < d.z(); ++z) {
        const VoxelKey k{m.x + x, m.y + y, m.z + z};
        const double vz = k.z * r;
        if (gt.support(k) && !gt.reachable(k) && vz > fz + 0.2 &&
            vz < std::min(fz + 1.8, next - 0.3)) {
          c = table, prio = 4;
        } else if (gt.reachable(k) && vz > (prev + fz) / 2 && vz < (fz + next) / 2 && prio < 3) {
          c = std::abs(vz - fz) <= 0.25 ? trav : trans, prio = 3;
        } else if (gt.occupied(k) && vz >= fz + 0.3 && vz <= std::min(fz + 1.8, next - 0.3) &&
                   prio < 2) {
          c = wall, prio = 2;
        }
      }
      fill_voxel(view, x, y, ppv, c);
    }
  return view;
}

View render_side(const GroundTruth& gt, int ppv) {
  const double r = gt.resolution();
  const VoxelKey m = gt.min_key();
  const Eigen::Vector3i d = gt.dims();
  View view(View::Kind::side, m.x * r, m.z * r, (m.x + d.x()) * r, (m.z + d.z()) * r, r / ppv);
  for (int z = 0; z < d.z(); ++z)
    for (int x = 0; x < d.x(); ++x) {
      int occ = 0;
      bool reach = false;
      for (int y = 0; y < d.y(); ++y) {
        const VoxelKey k{m.x + x, m.y + y, m.z + z};
        occ += gt.occupied(k) ? 1 : 0;
        reach = reach || gt.reachable(k);
      }
      if (occ == 0 && !reach) continue;
      const int shade = 220 - std::min(180, int(std::sqrt(double(occ)) * 12.0));
      const Rgb c =
          reach ? Rgb{60, 170, 60}
                : Rgb{uint8_t(shade), uint8_t(shade), uint8_t(shade + 10 > 255 ? 255 : shade + 10)};
      fill_voxel(view, x, z, ppv, c);
    }
  return view;
}

std::vector<std::string> render_scene(const GroundTruth& gt, const std::string& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw std::runtime_error(dir + ": cannot create directory: " + ec.message());
  std::vector<std::string> out;
  for (std::size_t i = 0; i < gt.floors().size(); ++i) {
    const std::string p = dir + "/floor_" + std::to_string(i) + ".png";
    render_floor(gt, int(i)).save_png(p);
    out.push_back(p);
  }
  const std::string p = dir + "/side.png";
  render_side(gt).save_png(p);
  out.push_back(p);
  return out;
}

}  // namespace storey::tools::sim
