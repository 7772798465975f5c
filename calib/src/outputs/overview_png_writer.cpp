#include "rigcal/calib/outputs/overview_png_writer.hpp"

#include <png.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <stdexcept>
#include <string>

#include "rigcal/calib/outputs/cloud_writers.hpp"
#include "rigcal/core/atomic_file.hpp"

namespace rigcal::calib {
namespace {

using Colour = std::array<std::uint8_t, 3>;
constexpr std::array<Colour, 6> kPalette = {{{255, 70, 70}, {60, 190, 255}, {255, 200, 0},
                                             {110, 255, 110}, {255, 90, 255}, {255, 140, 40}}};

// A 5x7 bitmap font (rows top to bottom, bit 4 = leftmost) for labels: A–Z, 0–9 and a little punctuation.
const std::map<char, std::array<std::uint8_t, 7>>& font() {
  static const std::map<char, std::array<std::uint8_t, 7>> glyphs = {
      {'A', {14, 17, 17, 31, 17, 17, 17}}, {'B', {30, 17, 17, 30, 17, 17, 30}}, {'C', {14, 17, 16, 16, 16, 17, 14}},
      {'D', {30, 17, 17, 17, 17, 17, 30}}, {'E', {31, 16, 16, 30, 16, 16, 31}}, {'F', {31, 16, 16, 30, 16, 16, 16}},
      {'G', {14, 17, 16, 23, 17, 17, 15}}, {'H', {17, 17, 17, 31, 17, 17, 17}}, {'I', {14, 4, 4, 4, 4, 4, 14}},
      {'J', {7, 2, 2, 2, 2, 18, 12}},      {'K', {17, 18, 20, 24, 20, 18, 17}}, {'L', {16, 16, 16, 16, 16, 16, 31}},
      {'M', {17, 27, 21, 21, 17, 17, 17}}, {'N', {17, 17, 25, 21, 19, 17, 17}}, {'O', {14, 17, 17, 17, 17, 17, 14}},
      {'P', {30, 17, 17, 30, 16, 16, 16}}, {'Q', {14, 17, 17, 17, 21, 18, 13}}, {'R', {30, 17, 17, 30, 20, 18, 17}},
      {'S', {15, 16, 16, 14, 1, 1, 30}},   {'T', {31, 4, 4, 4, 4, 4, 4}},       {'U', {17, 17, 17, 17, 17, 17, 14}},
      {'V', {17, 17, 17, 17, 17, 10, 4}},  {'W', {17, 17, 17, 21, 21, 21, 10}}, {'X', {17, 17, 10, 4, 10, 17, 17}},
      {'Y', {17, 17, 10, 4, 4, 4, 4}},     {'Z', {31, 1, 2, 4, 8, 16, 31}},     {'0', {14, 17, 19, 21, 25, 17, 14}},
      {'1', {4, 12, 4, 4, 4, 4, 14}},      {'2', {14, 17, 1, 2, 4, 8, 31}},     {'3', {31, 2, 4, 2, 1, 17, 14}},
      {'4', {2, 6, 10, 18, 31, 2, 2}},     {'5', {31, 16, 30, 1, 1, 17, 14}},   {'6', {6, 8, 16, 30, 17, 17, 14}},
      {'7', {31, 1, 2, 4, 8, 8, 8}},       {'8', {14, 17, 17, 14, 17, 17, 14}}, {'9', {14, 17, 17, 15, 1, 2, 12}},
      {'-', {0, 0, 0, 31, 0, 0, 0}},       {'_', {0, 0, 0, 0, 0, 0, 31}},       {'.', {0, 0, 0, 0, 0, 12, 12}},
      {':', {0, 12, 12, 0, 12, 12, 0}},    {'(', {2, 4, 8, 8, 8, 4, 2}},        {')', {8, 4, 2, 2, 2, 4, 8}},
      {'/', {1, 1, 2, 4, 8, 16, 16}},      {'=', {0, 0, 31, 0, 31, 0, 0}},
  };
  return glyphs;
}

/// Draws `text` (upper-cased) with its top-left at (x, y), each font pixel `scale` pixels wide.
void drawText(RgbImage& img, int x, int y, const std::string& text, Colour c, int scale = 2) {
  for (const char raw : text) {
    const char ch = char(std::toupper(static_cast<unsigned char>(raw)));
    const auto it = font().find(ch);
    if (it != font().end())
      for (int row = 0; row < 7; ++row)
        for (int col = 0; col < 5; ++col)
          if ((it->second[std::size_t(row)] >> (4 - col)) & 1)
            for (int dy = 0; dy < scale; ++dy)
              for (int dx = 0; dx < scale; ++dx) img.set(x + col * scale + dx, y + row * scale + dy, c[0], c[1], c[2]);
    x += 6 * scale;
  }
}

void drawRect(RgbImage& img, int x0, int y0, int x1, int y1, Colour c) {
  for (int x = x0; x <= x1; ++x) {
    img.set(x, y0, c[0], c[1], c[2]);
    img.set(x, y1, c[0], c[1], c[2]);
  }
  for (int y = y0; y <= y1; ++y) {
    img.set(x0, y, c[0], c[1], c[2]);
    img.set(x1, y, c[0], c[1], c[2]);
  }
}

/// Maps map-frame x (forward) / y (left) into a rectangle of the image: x up, y to the left.
struct View {
  double cx = 0, cy = 0, metres_per_px = 1;
  int left = 0, top = 0, size = 1;
  [[nodiscard]] bool toPixel(const Eigen::Vector3d& p, int& px, int& py) const {
    px = left + size / 2 + int(std::floor((cy - p.y()) / metres_per_px));
    py = top + size / 2 + int(std::floor((cx - p.x()) / metres_per_px));
    return px >= left && px < left + size && py >= top && py < top + size;
  }
};

void drawPoints(RgbImage& img, const View& v, const std::vector<Eigen::Vector3d>& pts, Colour c) {
  int px = 0, py = 0;
  for (const auto& p : pts)
    if (v.toPixel(p, px, py)) img.set(px, py, c[0], c[1], c[2]);
}

/// Grey by point density (log scale), so walls stand out of the ground.
void drawMap(RgbImage& img, const View& v, const std::vector<Eigen::Vector3d>& pts) {
  std::vector<int> count(std::size_t(v.size) * std::size_t(v.size), 0);
  int px = 0, py = 0;
  for (const auto& p : pts)
    if (v.toPixel(p, px, py)) ++count[std::size_t(py - v.top) * std::size_t(v.size) + std::size_t(px - v.left)];
  for (int y = 0; y < v.size; ++y)
    for (int x = 0; x < v.size; ++x) {
      const int n = count[std::size_t(y) * std::size_t(v.size) + std::size_t(x)];
      if (n == 0) continue;
      const auto g = std::uint8_t(std::min(230.0, 70.0 + 40.0 * std::log2(1.0 + n)));
      img.set(v.left + x, v.top + y, g, g, g);
    }
}

}  // namespace

void RgbImage::set(int x, int y, std::uint8_t r, std::uint8_t g, std::uint8_t b) {
  if (x < 0 || y < 0 || x >= width || y >= height) return;
  const std::size_t i = (std::size_t(y) * std::size_t(width) + std::size_t(x)) * 3;
  rgb[i] = r;
  rgb[i + 1] = g;
  rgb[i + 2] = b;
}

RgbImage renderOverview(const CalibrationOutcome& o, int panel_size) {
  const int header = 56;
  RgbImage img;
  img.width = 2 * panel_size + 10;
  img.height = panel_size + header;
  img.rgb.assign(std::size_t(img.width) * std::size_t(img.height) * 3, 18);

  const auto map = outcomeMapCloud(o, 0.05);
  std::vector<std::vector<Eigen::Vector3d>> before, after;
  for (const auto& d : o.datasets) {
    before.push_back(calibrationCloudInMap(d, d.T_mapping_calib_guess));
    const LidarLidarResult* r = o.lidar(d.calibration_sensor);
    after.push_back(calibrationCloudInMap(d, (r != nullptr && r->ok) ? r->T_mapping_calib : d.T_mapping_calib_guess));
  }
  // The view: the calibrated calibration points (else the map), square, with a margin.
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  const auto extend = [&](const std::vector<Eigen::Vector3d>& pts) {
    for (const auto& p : pts) {
      lo = lo.cwiseMin(p.head<2>());
      hi = hi.cwiseMax(p.head<2>());
    }
  };
  for (const auto& a : after) extend(a);
  if (!lo.allFinite()) extend(map);
  if (!lo.allFinite()) {
    lo.setZero();
    hi.setOnes();
  }
  const double span = std::max({hi.x() - lo.x(), hi.y() - lo.y(), 1.0}) + 4.0;
  View panels[2];
  for (int k = 0; k < 2; ++k) {
    panels[k].cx = 0.5 * (lo.x() + hi.x());
    panels[k].cy = 0.5 * (lo.y() + hi.y());
    panels[k].metres_per_px = span / panel_size;
    panels[k].left = k * (panel_size + 10);
    panels[k].top = header;
    panels[k].size = panel_size;
  }
  // The inset's feature: the 4 m square holding the most calibrated calibration points above the
  // ground (walls, poles, cars: where a misalignment shows; the ground rings near the car show nothing).
  std::vector<double> heights;
  for (const auto& a : after)
    for (const auto& p : a) heights.push_back(p.z());
  double ground = 0.0;
  if (!heights.empty()) {
    auto nth = heights.begin() + std::ptrdiff_t(heights.size() / 10);
    std::nth_element(heights.begin(), nth, heights.end());
    ground = *nth;
  }
  std::map<std::pair<long, long>, int> cells;
  for (const auto& a : after)
    for (const auto& p : a)
      if (p.z() > ground + 0.5) ++cells[{long(std::floor(p.x() / 4.0)), long(std::floor(p.y() / 4.0))}];
  std::pair<long, long> feature{0, 0};
  int most = -1;
  for (const auto& [cell, n] : cells)
    if (n > most) {
      most = n;
      feature = cell;
    }
  const int inset_size = std::max(100, panel_size * 3 / 8);
  for (int k = 0; k < 2; ++k) {
    const View& v = panels[k];
    drawMap(img, v, map);
    const auto& clouds = k == 0 ? before : after;
    for (std::size_t l = 0; l < clouds.size(); ++l) drawPoints(img, v, clouds[l], kPalette[l % kPalette.size()]);
    if (most > 0) {
      View inset;
      inset.cx = (double(feature.first) + 0.5) * 4.0;
      inset.cy = (double(feature.second) + 0.5) * 4.0;
      inset.metres_per_px = 4.0 / inset_size;
      inset.size = inset_size;
      inset.left = v.left + v.size - inset_size - 6;
      inset.top = v.top + v.size - inset_size - 6;
      // Outline the feature on the panel, then draw the inset over a cleared square.
      int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
      (void)v.toPixel({inset.cx + 2.0, inset.cy + 2.0, 0}, x0, y0);  // may lie off the panel: clipped when drawn
      (void)v.toPixel({inset.cx - 2.0, inset.cy - 2.0, 0}, x1, y1);
      drawRect(img, x0, y0, x1, y1, {255, 255, 255});
      for (int y = inset.top; y < inset.top + inset.size; ++y)
        for (int x = inset.left; x < inset.left + inset.size; ++x) img.set(x, y, 30, 30, 30);
      drawMap(img, inset, map);
      for (std::size_t l = 0; l < clouds.size(); ++l) drawPoints(img, inset, clouds[l], kPalette[l % kPalette.size()]);
      drawRect(img, inset.left - 1, inset.top - 1, inset.left + inset.size, inset.top + inset.size, {255, 255, 255});
      drawText(img, inset.left + 4, inset.top + 4, "ZOOM 4 M", {255, 255, 255}, 1);
    }
    drawText(img, v.left + 8, 6, k == 0 ? "BEFORE (INITIAL)" : "AFTER (CALIBRATED)", {255, 255, 255}, 3);
    char scale[64];
    std::snprintf(scale, sizeof scale, "%.0f M ACROSS", span);
    drawText(img, v.left + v.size - 6 * 2 * 14, 10, scale, {180, 180, 180}, 2);
  }
  // Legend: one colour per calibration lidar.
  int x = 8;
  for (std::size_t l = 0; l < o.datasets.size(); ++l) {
    const Colour c = kPalette[l % kPalette.size()];
    for (int dy = 0; dy < 10; ++dy)
      for (int dx = 0; dx < 10; ++dx) img.set(x + dx, 36 + dy, c[0], c[1], c[2]);
    drawText(img, x + 14, 35, o.datasets[l].calibration_sensor, c, 2);
    x += 14 + 12 * int(o.datasets[l].calibration_sensor.size()) + 20;
  }
  drawText(img, x, 35, "GREY: MAP (" + o.mapping_sensor + ")", {200, 200, 200}, 2);
  return img;
}

namespace {
// libpng writes through these into the atomic file's stream (which records any write error).
void pngWrite(png_structp png, png_bytep data, std::size_t size) {
  static_cast<std::ostream*>(png_get_io_ptr(png))->write(reinterpret_cast<const char*>(data), std::streamsize(size));
}
void pngFlush(png_structp) {}
}  // namespace

void writePng(const std::filesystem::path& path, const RgbImage& image) {
  AtomicFile file(path);
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png != nullptr ? png_create_info_struct(png) : nullptr;
  if (png == nullptr || info == nullptr || setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    throw std::runtime_error(path.string() + ": PNG encoding failed");
  }
  png_set_write_fn(png, &file.stream(), pngWrite, pngFlush);
  png_set_IHDR(png, info, png_uint_32(image.width), png_uint_32(image.height), 8, PNG_COLOR_TYPE_RGB,
               PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  for (int y = 0; y < image.height; ++y)
    png_write_row(png, image.rgb.data() + std::size_t(y) * std::size_t(image.width) * 3);
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  file.commit();
}

void writeOverviewPng(const std::filesystem::path& path, const CalibrationOutcome& outcome, int panel_size) {
  writePng(path, renderOverview(outcome, panel_size));
}

}  // namespace rigcal::calib
