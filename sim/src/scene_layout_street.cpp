// The street layout: the street follows the vehicle's path (extended straight beyond both ends), with
// a lane marking, parking lanes with parked cars, curbs, sidewalks with trees, light poles, signs and
// bollards, and a near-continuous frontage of buildings broken by alleys and one crossing.
#include <algorithm>
#include <cmath>

#include "scene_layout.hpp"

namespace rigcal::sim::detail {
namespace {

/// The street's centre line, parameterised by arc length.
class CentreLine {
 public:
  explicit CentreLine(const std::vector<Eigen::Vector2d>& path) {
    std::vector<Eigen::Vector2d> p;
    for (const auto& q : path)
      if (p.empty() || (q - p.back()).norm() > 0.5) p.push_back(q);
    if (p.size() < 2) p = {path.front(), path.front() + Eigen::Vector2d(1, 0)};
    const Eigen::Vector2d t0 = (p[1] - p[0]).normalized(), t1 = (p.back() - p[p.size() - 2]).normalized();
    points_.push_back(p.front() - kExtension * t0);
    points_.insert(points_.end(), p.begin(), p.end());
    points_.push_back(p.back() + kExtension * t1);
    s_.push_back(0);
    for (std::size_t i = 1; i < points_.size(); ++i) s_.push_back(s_.back() + (points_[i] - points_[i - 1]).norm());
  }
  [[nodiscard]] double length() const { return s_.back(); }
  [[nodiscard]] Eigen::Vector2d at(double s) const {
    const std::size_t i = segment(s);
    const double u = (s - s_[i]) / std::max(1e-9, s_[i + 1] - s_[i]);
    return points_[i] + std::clamp(u, 0.0, 1.0) * (points_[i + 1] - points_[i]);
  }
  [[nodiscard]] Eigen::Vector2d tangent(double s) const {
    const std::size_t i = segment(s);
    return (points_[i + 1] - points_[i]).normalized();
  }
  [[nodiscard]] Eigen::Vector2d left(double s) const {
    const Eigen::Vector2d t = tangent(s);
    return {-t.y(), t.x()};
  }
  [[nodiscard]] double yaw(double s) const {
    const Eigen::Vector2d t = tangent(s);
    return std::atan2(t.y(), t.x());
  }

 private:
  static constexpr double kExtension = 45.0;
  [[nodiscard]] std::size_t segment(double s) const {
    const auto it = std::upper_bound(s_.begin(), s_.end(), s);
    const std::size_t i = it == s_.begin() ? 0 : std::size_t(it - s_.begin()) - 1;
    return std::min(i, points_.size() - 2);
  }
  std::vector<Eigen::Vector2d> points_;
  std::vector<double> s_;
};

Rect2 around(const Eigen::Vector2d& p, double r) { return {p.x() - r, p.y() - r, p.x() + r, p.y() + r}; }

void sideOfStreet(const CentreLine& line, double side, double curb, double crossing, ObjectBuilder& build,
                  Placer& place, Rng& rng) {
  const double total = line.length();
  const auto off = [&](double s, double d) { return Eigen::Vector2d(line.at(s) + side * d * line.left(s)); };
  // The frontage first (the biggest things): buildings set back behind the sidewalk, with alleys
  // between some of them.
  for (double s = rng.uniform(0, 5); s < total;) {
    const double len = rng.uniform(10, 28), depth = rng.uniform(9, 16);
    const double d = curb + rng.uniform(3.5, 5.5) + 0.5 * depth;
    const double mid = s + 0.5 * len;
    if (std::abs(mid - crossing) > 0.5 * len + 8) {
      const Eigen::Vector2d c = off(mid, d);
      const double yaw = line.yaw(mid) + (side > 0 ? M_PI : 0);  // front faces the street
      if (place.free(rotatedRect(c, yaw, len, depth), 0.2)) {
        // Draws in separate statements: argument evaluation order is unspecified (compilers differ).
        const bool l_shape = rng.chance(0.3);
        const int floors = int(rng.uniformInt(2, 5));
        place.occupy(build.building(c, yaw, len, depth, floors, l_shape));
      }
    }
    s += len + (rng.chance(0.4) ? rng.uniform(3, 7) : 0.6);
  }
  // Parked cars in the parking lane.
  for (double s = rng.uniform(1, 6); s < total - 3; s += rng.uniform(5.6, 8.5)) {
    if (std::abs(s - crossing) < 12 || !rng.chance(0.55)) continue;
    const Eigen::Vector2d c = off(s, curb - rng.uniform(1.2, 1.4));
    const double yaw = line.yaw(s) + (side > 0 ? 0.0 : M_PI) + rng.uniform(-0.04, 0.04);
    if (place.free(rotatedRect(c, yaw, 4.9, 1.9), 0.1)) place.occupy(build.car(c, yaw));
  }
  // Curb stones, interrupted at the crossing.
  for (double s = 0; s + 3 <= total; s += 3) {
    if (std::abs(s - crossing) < 8) continue;
    const Eigen::Vector2d a = off(s, curb), b = off(s + 3, curb);
    const Rect2 r{std::min(a.x(), b.x()), std::min(a.y(), b.y()), std::max(a.x(), b.x()), std::max(a.y(), b.y())};
    if (place.free(r, -0.05)) place.occupy(build.curb(a, b));
  }
  // Sidewalk furniture: trees, light poles, signs, bollards.
  for (double s = rng.uniform(2, 8); s < total; s += rng.uniform(8, 14)) {
    const Eigen::Vector2d p = off(s, curb + rng.uniform(1.2, 1.8));
    if (place.free(around(p, 3.0), -2.2)) place.occupy(build.tree(p));
  }
  for (double s = rng.uniform(5, 15); s < total; s += rng.uniform(22, 30)) {
    const Eigen::Vector2d p = off(s, curb + 0.5);
    if (place.free(around(p, 0.5), 0.1)) place.occupy(build.lightPole(p, line.yaw(s) + side * M_PI_2 + M_PI));
  }
  for (double s = rng.uniform(10, 30); s < total; s += rng.uniform(25, 50)) {
    const Eigen::Vector2d p = off(s, curb + 0.4);
    if (place.free(around(p, 0.5), 0.1)) place.occupy(build.sign(p, line.yaw(s) + (side > 0 ? M_PI : 0)));
  }
  for (double s = crossing - 9; s <= crossing + 9; s += 18)
    for (int k = 0; k < 4; ++k) {
      const Eigen::Vector2d p = off(s + (s < crossing ? -1.5 * k : 1.5 * k), curb + 0.4);
      if (place.free(around(p, 0.2), 0.05)) place.occupy(build.bollard(p));
    }
}

}  // namespace

void layoutStreet(const SceneSpec& /*spec*/, ObjectBuilder& build, Placer& place, Rng& rng) {
  const CentreLine line(place.path());
  const double curb = rng.uniform(5.4, 6.2);
  const double crossing = line.length() * rng.uniform(0.3, 0.7);
  // Road paint: a dashed centre line and stop lines at the crossing.
  for (double s = 0; s + 3 < line.length(); s += 9) {
    if (std::abs(s - crossing) < 9) continue;
    build.paint(line.at(s + 1.5), line.yaw(s + 1.5), 3.0, 0.15);
  }
  for (const double s : {crossing - 8.5, crossing + 8.5})
    build.paint(line.at(s), line.yaw(s) + M_PI_2, 2 * curb - 1.0, 0.4);
  sideOfStreet(line, 1.0, curb, crossing, build, place, rng);
  sideOfStreet(line, -1.0, curb, crossing, build, place, rng);
}

}  // namespace rigcal::sim::detail
