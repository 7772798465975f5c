// The parking-lot layout: a lot of painted stall rows with parked cars, planted islands with trees and
// light poles, and on its four sides (assigned at random, so no two seeds look alike and no scene is
// symmetric) a row of shops, one large L-shaped building, a wall lined with trees, and a fenced street
// edge with poles, signs and bollards.
#include <array>
#include <cmath>

#include "scene_layout.hpp"

namespace rigcal::sim::detail {
namespace {

enum class SideKind { kShops, kLargeBuilding, kWallAndTrees, kStreetEdge };

struct Side {
  Eigen::Vector2d start, t, n;  // corner, direction along the side, inward normal (left of t)
  double length;
  [[nodiscard]] Eigen::Vector2d at(double s, double d) const { return start + s * t + d * n; }
  [[nodiscard]] double yaw() const { return std::atan2(t.y(), t.x()); }
};

void shops(const Side& side, ObjectBuilder& build, Placer& place, Rng& rng) {
  double s = rng.uniform(2, 8);
  while (s < side.length - 12) {
    const double len = std::min(rng.uniform(14, 32), side.length - s - 2);
    const double depth = rng.uniform(10, 16), setback = rng.uniform(0.5, 3);
    const Eigen::Vector2d c = side.at(s + 0.5 * len, setback + 0.5 * depth);
    const Rect2 fp = rotatedRect(c, side.yaw(), len, depth);
    if (len > 8 && place.free(fp)) {
      // Draws in separate statements: argument evaluation order is unspecified (compilers differ).
      const bool l_shape = rng.chance(0.35);
      const int floors = int(rng.uniformInt(1, 4));
      place.occupy(build.building(c, side.yaw(), len, depth, floors, l_shape));
      // Bollards guarding the shop front.
      const int n = int(rng.uniformInt(0, 5));
      const double d = setback + depth + rng.uniform(1.8, 2.6), s0 = s + rng.uniform(2, len * 0.5);
      for (int k = 0; k < n; ++k) {
        const Eigen::Vector2d p = side.at(s0 + 1.6 * k, d);
        const Rect2 r{p.x() - 0.2, p.y() - 0.2, p.x() + 0.2, p.y() + 0.2};
        if (place.free(r, 0.1)) place.occupy(build.bollard(p));
      }
    }
    s += len + rng.uniform(3, 9);
  }
  // A curb separating the shop frontage from the lot, with gaps for access.
  double c = 0;
  while (c < side.length) {
    const double len = rng.uniform(6, 18);
    const Eigen::Vector2d a = side.at(c, 20.5), b = side.at(std::min(c + len, side.length), 20.5);
    const Rect2 r{std::min(a.x(), b.x()) - 0.2, std::min(a.y(), b.y()) - 0.2, std::max(a.x(), b.x()) + 0.2,
                  std::max(a.y(), b.y()) + 0.2};
    if (place.free(r, 0.0)) place.occupy(build.curb(a, b));
    c += len + rng.uniform(4, 8);
  }
}

void largeBuilding(const Side& side, ObjectBuilder& build, Placer& place, Rng& rng) {
  const double len = side.length * rng.uniform(0.45, 0.7), depth = rng.uniform(14, 20);
  const double s = rng.uniform(3, side.length - len - 3);
  const Eigen::Vector2d c = side.at(s + 0.5 * len, 1 + 0.5 * depth);
  if (place.free(rotatedRect(c, side.yaw(), len, depth)))
    place.occupy(build.building(c, side.yaw(), len, depth, int(rng.uniformInt(2, 5)), true));
  // Loading area beside it: a wall stub and a couple of signs.
  const double s2 = s + len + rng.uniform(4, 8);
  if (s2 + 10 < side.length) {
    const Eigen::Vector2d a = side.at(s2, 0.5), b = side.at(s2, rng.uniform(8, 14));
    const Rect2 r = rotatedRect(0.5 * (a + b), side.yaw() + M_PI_2, (b - a).norm(), 0.4);
    if (place.free(r)) place.occupy(build.wall(a, b, rng.uniform(1.8, 3.0), 0.3, Material::kConcrete));
  }
}

void wallAndTrees(const Side& side, ObjectBuilder& build, Placer& place, Rng& rng) {
  double s = 0;
  while (s < side.length) {
    const double len = std::min(rng.uniform(10, 30), side.length - s);
    const Eigen::Vector2d a = side.at(s, 0.4), b = side.at(s + len, 0.4);
    const Rect2 r = rotatedRect(0.5 * (a + b), side.yaw(), len, 0.5);
    if (len > 2 && place.free(r, 0.0)) place.occupy(build.wall(a, b, rng.uniform(1.2, 2.6), 0.3, Material::kBrick));
    s += len + rng.uniform(2.5, 5);  // gates
  }
  for (double t = rng.uniform(2, 6); t < side.length - 2; t += rng.uniform(5, 11)) {
    const Eigen::Vector2d p = side.at(t, rng.uniform(3, 5));
    if (place.free({p.x() - 3, p.y() - 3, p.x() + 3, p.y() + 3}, -2.0)) place.occupy(build.tree(p));
  }
}

void streetEdge(const Side& side, ObjectBuilder& build, Placer& place, Rng& rng) {
  for (double t = rng.uniform(3, 10); t < side.length - 3; t += rng.uniform(16, 26)) {
    const Eigen::Vector2d p = side.at(t, 1.5);
    const Rect2 r{p.x() - 2.5, p.y() - 2.5, p.x() + 2.5, p.y() + 2.5};
    if (place.free(r, 0.0)) place.occupy(build.lightPole(p, side.yaw() + M_PI_2));
  }
  for (double t = rng.uniform(5, 15); t < side.length - 5; t += rng.uniform(12, 30)) {
    const Eigen::Vector2d p = side.at(t, 2.5);
    if (place.free({p.x() - 0.5, p.y() - 0.5, p.x() + 0.5, p.y() + 0.5}))
      place.occupy(build.sign(p, side.yaw() + M_PI_2 + rng.uniform(-0.3, 0.3)));
  }
  // A bollard line along the edge, with a gap for the entrance.
  const double gap = rng.uniform(0.3, 0.7) * side.length;
  for (double t = 1; t < side.length - 1; t += rng.uniform(1.8, 2.4)) {
    if (std::abs(t - gap) < 5) continue;
    const Eigen::Vector2d p = side.at(t, 0.6);
    const Rect2 r{p.x() - 0.2, p.y() - 0.2, p.x() + 0.2, p.y() + 0.2};
    if (place.free(r, 0.1)) place.occupy(build.bollard(p));
  }
}

void stallRows(const SceneSpec& spec, ObjectBuilder& build, Placer& place, Rng& rng) {
  // The sides take up to ~21 m (setback + building depth): the stalls keep 30 m from the edges.
  const double x0 = spec.center.x() - 0.5 * spec.size.x() + 30, x1 = spec.center.x() + 0.5 * spec.size.x() - 30;
  const double y0 = spec.center.y() - 0.5 * spec.size.y() + 30, y1 = spec.center.y() + 0.5 * spec.size.y() - 28;
  const double stall_w = rng.uniform(2.4, 2.7), stall_d = 5.0, aisle = rng.uniform(6.5, 7.5);
  for (double yc = y0 + rng.uniform(0, 4); yc < y1; yc += 2 * stall_d + aisle) {
    // Islands at both ends of the double row, with a tree and a light pole.
    for (const double xe : {x0 - 2.5, x1 + 2.5}) {
      const Eigen::Vector2d c(xe, yc);
      const Rect2 r = rotatedRect(c, 0, 4, 2 * stall_d);
      if (!place.free(r, 0.0)) continue;
      place.occupy(build.island(c, 0, 4, 2 * stall_d));
      // Crowns and lamp arms overhang the island: they too must keep clear of the path.
      const Eigen::Vector2d t = c + Eigen::Vector2d(0, rng.uniform(1.5, 3.5)), l = c - Eigen::Vector2d(0, 2.5);
      if (place.clearOfPath({t.x() - 3, t.y() - 3, t.x() + 3, t.y() + 3})) build.tree(t);
      if (place.clearOfPath({l.x() - 2.6, l.y() - 2.6, l.x() + 2.6, l.y() + 2.6}))
        build.lightPole(l, rng.chance(0.5) ? 0 : M_PI);
    }
    for (double x = x0; x + stall_w <= x1; x += stall_w) {
      for (const double side : {-1.0, 1.0}) {
        const Eigen::Vector2d line(x, yc + side * 0.5 * stall_d), stall(x + 0.5 * stall_w, yc + side * 0.5 * stall_d);
        if (place.clearOfPath(rotatedRect(line, M_PI_2, stall_d, 0.12))) build.paint(line, M_PI_2, stall_d, 0.12);
        if (!rng.chance(0.62)) continue;
        // Parked nose-in or reversed in, a little off-centre and askew, as people park.
        const double facing = rng.chance(0.7) ? side : -side;
        const double yaw = facing * M_PI_2 + rng.uniform(-0.06, 0.06);
        const double off_y = side * rng.uniform(-0.2, 0.1), off_x = rng.uniform(-0.15, 0.15);
        const Eigen::Vector2d c = stall + Eigen::Vector2d(off_x, off_y);
        const Rect2 fp = rotatedRect(c, yaw, 4.9, 1.9);
        if (place.free(fp, 0.05)) place.occupy(build.car(c, yaw));
      }
    }
    // The row's centre line.
    const Eigen::Vector2d mid(0.5 * (x0 + x1), yc);
    if (place.clearOfPath(rotatedRect(mid, 0, x1 - x0, 0.12))) build.paint(mid, 0, x1 - x0, 0.12);
  }
}

}  // namespace

void layoutParkingLot(const SceneSpec& spec, ObjectBuilder& build, Placer& place, Rng& rng) {
  const double w = spec.size.x(), h = spec.size.y();
  const Eigen::Vector2d lo = spec.center - 0.5 * spec.size, hi = spec.center + 0.5 * spec.size;
  const std::array<Side, 4> sides{{
      {lo, {1, 0}, {0, 1}, w},
      {{hi.x(), lo.y()}, {0, 1}, {-1, 0}, h},
      {hi, {-1, 0}, {0, -1}, w},
      {{lo.x(), hi.y()}, {0, -1}, {1, 0}, h},
  }};
  std::array<SideKind, 4> kinds{SideKind::kShops, SideKind::kLargeBuilding, SideKind::kWallAndTrees,
                                SideKind::kStreetEdge};
  for (std::size_t i = kinds.size() - 1; i > 0; --i) std::swap(kinds[i], kinds[std::size_t(rng.uniformInt(0, std::int64_t(i)))]);
  // Stalls first: the lot is what the vehicle drives through; the sides fill in around it.
  stallRows(spec, build, place, rng);
  for (std::size_t i = 0; i < sides.size(); ++i) {
    switch (kinds[i]) {
      case SideKind::kShops: shops(sides[i], build, place, rng); break;
      case SideKind::kLargeBuilding: largeBuilding(sides[i], build, place, rng); break;
      case SideKind::kWallAndTrees: wallAndTrees(sides[i], build, place, rng); break;
      case SideKind::kStreetEdge: streetEdge(sides[i], build, place, rng); break;
    }
  }
  // A few free-standing trees and signs scattered over the lot's margins.
  for (int k = 0; k < 10; ++k) {
    const double py = rng.uniform(lo.y() + 6, hi.y() - 6), px = rng.uniform(lo.x() + 6, hi.x() - 6);
    const Eigen::Vector2d p(px, py);
    const Rect2 r{p.x() - 3, p.y() - 3, p.x() + 3, p.y() + 3};
    if (!place.free(r)) continue;
    place.occupy(k % 3 == 0 ? build.sign(p, rng.uniform(0, 2 * M_PI)) : build.tree(p));
  }
}

}  // namespace rigcal::sim::detail
