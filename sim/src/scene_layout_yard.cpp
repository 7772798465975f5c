// The container-yard layout: blocks of shipping containers stacked one to four high (each box a little
// offset on the one below, as real stacks are), loading ramps rising to docks, pallet piles and tall
// light masts, over a sloped yard. Most of what a lidar sees here is steel walls at many heights and
// ground that is not level: a tilted or sideways lidar sees stacks above and below its own height.
#include <algorithm>
#include <cmath>

#include "scene_layout.hpp"

namespace rigcal::sim::detail {
namespace {

constexpr double kContainerWidth = 2.44, kContainerHeight = 2.59;

/// One stack of `tiers` containers (20 ft or 40 ft) standing at `c`; each tier is shifted and turned a
/// little on the one below. Returns its footprint.
Rect2 containerStack(Eigen::Vector2d c, double yaw, double length, int tiers, SceneContent& content,
                     const ObjectBuilder& build, Rng& rng) {
  const Rect2 fp = rotatedRect(c, yaw, length + 0.2, kContainerWidth + 0.2);
  double z = build.groundBelow(fp) + 0.15;
  for (int t = 0; t < tiers; ++t) {
    const Eigen::Vector2d o = c + Eigen::Vector2d(rng.uniform(-0.08, 0.08), rng.uniform(-0.08, 0.08));
    const double y = yaw + rng.uniform(-0.01, 0.01);
    content.boxes.push_back(Box::make(o.x(), o.y(), y, length, kContainerWidth, z, z + kContainerHeight,
                                      Material::kMetal));
    // Corner castings and door bars make the end faces uneven: a short frame proud of each end.
    for (const double end : {-0.5, 0.5}) {
      const Eigen::Vector2d e = o + end * (length + 0.06) * Eigen::Vector2d(std::cos(y), std::sin(y));
      content.boxes.push_back(Box::make(e.x(), e.y(), y, 0.06, kContainerWidth, z, z + 0.2, Material::kMetal));
    }
    z += kContainerHeight;
  }
  return fp;
}

/// A loading ramp: `steps` shallow terraces (0.5 m deep, rising `rise` each) up to a dock slab. At lidar
/// resolution the terraces read as a slope of rise/0.5.
Rect2 ramp(Eigen::Vector2d start, double yaw, int steps, double rise, double width, SceneContent& content,
           const ObjectBuilder& build) {
  const Eigen::Vector2d t(std::cos(yaw), std::sin(yaw));
  const double run = 0.5, dock = 4.0, length = steps * run + dock;
  const Rect2 fp = rotatedRect(start + 0.5 * length * t, yaw, length, width);
  const double z0 = build.groundBelow(fp);
  for (int k = 0; k < steps; ++k) {
    const Eigen::Vector2d c = start + (k + 0.5) * run * t;
    content.boxes.push_back(Box::make(c.x(), c.y(), yaw, run, width, z0, z0 + 0.15 + (k + 1) * rise,
                                      Material::kConcrete));
  }
  const Eigen::Vector2d d = start + (steps * run + 0.5 * dock) * t;
  content.boxes.push_back(Box::make(d.x(), d.y(), yaw, dock, width, z0, z0 + 0.15 + steps * rise, Material::kConcrete));
  return fp;
}

}  // namespace

void layoutContainerYard(const SceneSpec& spec, ObjectBuilder& build, SceneContent& content, Placer& place,
                         Rng& rng) {
  const Eigen::Vector2d lo = spec.center - 0.5 * spec.size, hi = spec.center + 0.5 * spec.size;
  // Loading ramps up to docks, turned every way, placed first so that the stacks fill in around them.
  for (int k = 0; k < 14; ++k) {
    const Eigen::Vector2d p(rng.uniform(lo.x() + 8, hi.x() - 8), rng.uniform(lo.y() + 8, hi.y() - 8));
    const double yaw = rng.uniform(0, 2 * M_PI);
    const int steps = int(rng.uniformInt(8, 16));
    const double rise = rng.uniform(0.05, 0.09), width = rng.uniform(3, 5);
    const Eigen::Vector2d t(std::cos(yaw), std::sin(yaw));
    const Rect2 fp = rotatedRect(p + 0.5 * (steps * 0.5 + 4.0) * t, yaw, steps * 0.5 + 4.0, width);
    if (place.free(fp, 0.5)) place.occupy(ramp(p, yaw, steps, rise, width, content, build));
  }
  // Blocks of stacks in rows along x with 9-14 m lanes between them; stacks left out here and there.
  for (double y = lo.y() + 4; y < hi.y() - 4; y += rng.uniform(9, 14) + 2 * kContainerWidth) {
    for (double x = lo.x() + 4; x < hi.x() - 14;) {
      const bool forty = rng.chance(0.6);
      const double len = forty ? 12.19 : 6.06;
      for (const double row : {0.0, kContainerWidth + 0.3}) {
        const Eigen::Vector2d c(x + 0.5 * len, y + row + 0.5 * kContainerWidth);
        const Rect2 fp = rotatedRect(c, 0, len + 0.2, kContainerWidth + 0.2);
        if (rng.chance(0.15) || !place.free(fp, 0.1)) continue;
        const int tiers = int(rng.uniformInt(1, 4));
        place.occupy(containerStack(c, rng.uniform(-0.01, 0.01), len, tiers, content, build, rng));
      }
      x += len + rng.uniform(0.4, 2.5);
    }
  }
  // Pallet piles (stepped, 0.15 m pallets) and light masts.
  for (int k = 0; k < 30; ++k) {
    const Eigen::Vector2d p(rng.uniform(lo.x() + 3, hi.x() - 3), rng.uniform(lo.y() + 3, hi.y() - 3));
    const Rect2 r{p.x() - 1.6, p.y() - 1.6, p.x() + 1.6, p.y() + 1.6};
    if (!place.free(r, 0.3)) continue;
    if (k % 4 == 0) {
      place.occupy(build.lightPole(p, rng.uniform(0, 2 * M_PI)));
      continue;
    }
    const double z0 = build.groundBelow(r) + 0.15, yaw = rng.uniform(0, M_PI);
    const int layers = int(rng.uniformInt(2, 9));
    for (int l = 0; l < layers; ++l) {
      const double shrink = 0.12 * l;
      content.boxes.push_back(Box::make(p.x(), p.y(), yaw + rng.uniform(-0.05, 0.05), 2.4 - shrink, 2.0 - shrink,
                                        z0 + 0.15 * l, z0 + 0.15 * (l + 1), Material::kBark));
    }
    place.occupy(r);
  }
  // A perimeter wall with gaps, so the yard has an edge.
  const Eigen::Vector2d corners[4] = {lo, {hi.x(), lo.y()}, hi, {lo.x(), hi.y()}};
  for (int s = 0; s < 4; ++s) {
    const Eigen::Vector2d a = corners[s], b = corners[(s + 1) % 4];
    const double len = (b - a).norm();
    for (double u = 0; u < len;) {
      const double seg = std::min(rng.uniform(15, 35), len - u);
      const Eigen::Vector2d p = a + (b - a) * (u / len), q = a + (b - a) * ((u + seg) / len);
      const Rect2 r = rotatedRect(0.5 * (p + q), std::atan2(b.y() - a.y(), b.x() - a.x()), seg, 0.5);
      if (seg > 2 && place.free(r, 0.0)) place.occupy(build.wall(p, q, rng.uniform(2.0, 3.5), 0.3, Material::kConcrete));
      u += seg + rng.uniform(3, 6);
    }
  }
}

}  // namespace rigcal::sim::detail
