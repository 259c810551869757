#include "tools/eval/coverage_plot.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "tools/sim/render.hpp"

namespace storey::tools::eval {

using sim::Image;
using sim::Rgb;

CoverageCurve mean_coverage_curve(const std::vector<const RunOutcome*>& runs, double dt,
                                  double t_end) {
  CoverageCurve c;
  std::vector<const RunOutcome*> used;
  for (const RunOutcome* r : runs)
    if (r && r->status == RunStatus::finished && !r->metrics.coverage_over_time.empty())
      used.push_back(r);
  c.runs = used.size();
  if (used.empty() || !(dt > 0) || !(t_end >= 0)) return c;
  const size_t n = size_t(std::floor(t_end / dt + 1e-9)) + 1;
  c.t.resize(n);
  c.mean.assign(n, 0.0);
  for (const RunOutcome* r : used) {
    const auto& s = r->metrics.coverage_over_time;
    size_t j = 0;  // samples s[0..j) have t <= grid time
    for (size_t k = 0; k < n; ++k) {
      const double t = double(k) * dt;
      while (j < s.size() && s[j].first <= t + 1e-9) ++j;
      c.mean[k] += j == 0 ? 0.0 : s[j - 1].second;
    }
  }
  for (size_t k = 0; k < n; ++k) {
    c.t[k] = double(k) * dt;
    c.mean[k] /= double(used.size());
  }
  return c;
}

namespace {

// 5x7 glyphs, one string of 7 rows x 5 columns each; lower case drawn as upper case.
struct Glyph {
  char c;
  const char* rows;
};
constexpr Glyph kFont[] = {
    {'0', ".###.#...##..###.#.###..##...#.###."}, {'1', "..#...##....#....#....#....#...###."},
    {'2', ".###.#...#....#...#...#...#...#####"}, {'3', "#####...#...#.....#.....##...#.###."},
    {'4', "...#...##..#.#.#..#.#####...#....#."}, {'5', "######....####.....#....##...#.###."},
    {'6', "..##..#...#....####.#...##...#.###."}, {'7', "#####....#...#...#...#....#....#..."},
    {'8', ".###.#...##...#.###.#...##...#.###."}, {'9', ".###.#...##...#.####....#...#..##.."},
    {'A', ".###.#...##...#######...##...##...#"}, {'B', "####.#...##...#####.#...##...#####."},
    {'C', ".###.#...##....#....#....#...#.###."}, {'D', "###..#..#.#...##...##...##..#.###.."},
    {'E', "######....#....####.#....#....#####"}, {'F', "######....#....####.#....#....#...."},
    {'G', ".###.#...##....#.####...##...#.####"}, {'H', "#...##...##...#######...##...##...#"},
    {'I', ".###...#....#....#....#....#...###."}, {'J', "..###...#....#....#....#.#..#..##.."},
    {'K', "#...##..#.#.#..##...#.#..#..#.#...#"}, {'L', "#....#....#....#....#....#....#####"},
    {'M', "#...###.###.#.##.#.##...##...##...#"}, {'N', "#...##...###..##.#.##..###...##...#"},
    {'O', ".###.#...##...##...##...##...#.###."}, {'P', "####.#...##...#####.#....#....#...."},
    {'Q', ".###.#...##...##...##.#.##..#..##.#"}, {'R', "####.#...##...#####.#.#..#..#.#...#"},
    {'S', ".#####....#.....###.....#....#####."}, {'T', "#####..#....#....#....#....#....#.."},
    {'U', "#...##...##...##...##...##...#.###."}, {'V', "#...##...##...##...##...#.#.#...#.."},
    {'W', "#...##...##...##.#.##.#.##.#.#.#.#."}, {'X', "#...##...#.#.#...#...#.#.#...##...#"},
    {'Y', "#...##...#.#.#...#....#....#....#.."}, {'Z', "#####....#...#...#...#...#....#####"},
    {'-', "................###................"}, {'_', "..............................#####"},
    {'.', "..........................##...##.."}, {',', ".....................##....#...#..."},
    {'%', "##...##..#...#...#...#...#..##...##"}, {'(', "...#...#...#....#....#.....#.....#."},
    {')', ".#.....#.....#....#....#...#...#..."}, {'[', ".###..#....#....#....#....#....###."},
    {']', ".###....#....#....#....#....#..###."}, {'/', ".........#...#...#...#...#........."},
    {':', "......##...##........##...##......."}, {'+', ".......#....#..#####..#....#......."},
    {'=', "..........#####.....#####.........."},
};

const char* glyph(char c) {
  c = char(std::toupper(static_cast<unsigned char>(c)));
  for (const auto& g : kFont)
    if (g.c == c) return g.rows;
  return nullptr;  // space and unknown characters: blank
}

// Text with its top-left corner at (x, y); glyphs 5x7 pixels times `scale`, 1 column apart.
void draw_text(Image& img, int x, int y, const std::string& s, Rgb col, int scale = 1) {
  for (const char ch : s) {
    if (const char* rows = glyph(ch)) {
      const size_t len = std::strlen(rows);
      for (int r = 0; r < 7; ++r)
        for (int c = 0; c < 5; ++c) {
          const size_t idx = size_t(r * 5 + c);
          if (idx < len && rows[idx] == '#')
            for (int dy = 0; dy < scale; ++dy)
              for (int dx = 0; dx < scale; ++dx)
                img.set(x + c * scale + dx, y + r * scale + dy, col);
        }
    }
    x += 6 * scale;
  }
}
int text_width(const std::string& s, int scale = 1) {
  return int(s.size()) * 6 * scale;
}

void fill_rect(Image& img, int x0, int y0, int x1, int y1, Rgb c) {
  for (int y = y0; y <= y1; ++y)
    for (int x = x0; x <= x1; ++x) img.set(x, y, c);
}

// 1, 2 or 5 times a power of ten, so that about `target` ticks span `range`.
double nice_step(double range, int target) {
  const double raw = range / std::max(1, target);
  const double p = std::pow(10.0, std::floor(std::log10(raw)));
  for (const double m : {1.0, 2.0, 5.0, 10.0})
    if (m * p >= raw) return m * p;
  return 10 * p;
}

}  // namespace

void write_coverage_plot(const std::string& path, const std::string& title,
                         const std::vector<CoverageCurve>& curves) {
  // Colour-blind-friendly palette (Okabe-Ito), then greys.
  static const Rgb palette[] = {{0, 114, 178}, {213, 94, 0},   {0, 158, 115}, {204, 121, 167},
                                {230, 159, 0}, {86, 180, 233}, {0, 0, 0},     {120, 120, 120}};
  // The legend sets the width: the plot area stays 640 px, the longest label fits beside it.
  auto legend_label = [](const CoverageCurve& c) {
    return c.label + " (" + std::to_string(c.runs) + ")";
  };
  int legend_w = 0;
  for (const auto& c : curves) legend_w = std::max(legend_w, text_width(legend_label(c), 2));
  const int left = 70, top = 44, bottom = 60, right = std::max(250, 60 + legend_w);
  const int W = left + 640 + right;
  const int H = std::max(540, top + bottom + 16 + 24 * int(curves.size()));
  const int px0 = left, px1 = W - right, py0 = top, py1 = H - bottom;
  Image img(W, H);
  const Rgb ink{30, 30, 30}, grid{225, 225, 225};

  double t_max = 0;
  for (const auto& c : curves)
    if (!c.t.empty()) t_max = std::max(t_max, c.t.back());
  if (t_max <= 0) t_max = 1;
  const double tstep = nice_step(t_max, 6);
  t_max = std::ceil(t_max / tstep - 1e-9) * tstep;
  auto X = [&](double t) { return px0 + int(std::lround((px1 - px0) * t / t_max)); };
  auto Y = [&](double cov) { return py1 - int(std::lround((py1 - py0) * cov)); };

  for (int k = 0; k <= 10; ++k) {  // coverage grid every 10 %, labels every 20 %
    const int y = Y(k / 10.0);
    img.line(px0, y, px1, y, grid);
    if (k % 2 == 0) {
      const std::string l = std::to_string(k * 10);
      draw_text(img, px0 - 8 - text_width(l, 2), y - 7, l, ink, 2);
    }
  }
  for (double t = 0; t <= t_max + 1e-9; t += tstep) {
    const int x = X(t);
    img.line(x, py0, x, py1, grid);
    char b[32];
    std::snprintf(b, sizeof b, "%g", t);
    draw_text(img, x - text_width(b, 2) / 2, py1 + 8, b, ink, 2);
  }
  img.line(px0, py1, px1, py1, ink);
  img.line(px0, py0, px0, py1, ink);
  draw_text(img, (px0 + px1) / 2 - text_width("time [s]", 2) / 2, H - 24, "time [s]", ink, 2);
  draw_text(img, 8, 8, "coverage [%]", ink, 2);
  draw_text(img, px0 + 150, 8, title, ink, 2);

  for (size_t i = 0; i < curves.size(); ++i) {
    const Rgb col = palette[i % (sizeof palette / sizeof palette[0])];
    const auto& c = curves[i];
    for (size_t k = 1; k < c.t.size(); ++k) {
      const int x0 = X(c.t[k - 1]), y0 = Y(c.mean[k - 1]), x1 = X(c.t[k]), y1 = Y(c.mean[k]);
      img.line(x0, y0, x1, y1, col);  // 2 px thick
      img.line(x0, y0 - 1, x1, y1 - 1, col);
    }
    const int ly = py0 + 8 + int(i) * 24;
    fill_rect(img, px1 + 16, ly + 2, px1 + 36, ly + 10, col);
    draw_text(img, px1 + 44, ly, legend_label(c), ink, 2);
  }
  img.save_png(path);
}

}  // namespace storey::tools::eval
