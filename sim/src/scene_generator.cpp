#include "rigcal/sim/scene_generator.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "scene_layout.hpp"

namespace rigcal::sim {
namespace detail {

namespace {
double distanceToRect(const Eigen::Vector2d& p, const Rect2& r) {
  const double dx = std::max({r.x0 - p.x(), 0.0, p.x() - r.x1});
  const double dy = std::max({r.y0 - p.y(), 0.0, p.y() - r.y1});
  return std::hypot(dx, dy);
}
}  // namespace

bool Placer::clearOfPath(const Rect2& r) const {
  return std::all_of(path_.begin(), path_.end(), [&](const auto& p) { return distanceToRect(p, r) >= clearance_; });
}

bool Placer::free(const Rect2& r, double margin) const {
  if (!clearOfPath(r)) return false;
  return std::none_of(taken_.begin(), taken_.end(), [&](const Rect2& t) {
    return r.x0 < t.x1 + margin && t.x0 < r.x1 + margin && r.y0 < t.y1 + margin && t.y0 < r.y1 + margin;
  });
}

}  // namespace detail

std::vector<std::string> sceneLayouts() {
  return {"parking-lot", "street", "container-yard", "empty", "calibration-bay", "bay-one-wall"};
}

Ground makeGround(const SceneSpec& spec, std::uint64_t seed) {
  Rng rng(hashKeys(seed, 0x67726f756e64ULL));  // "ground"
  const double dir = rng.uniform(0, 2 * M_PI), grade = spec.slope_percent * 0.01;
  GroundSpec g;
  g.slope = grade * Eigen::Vector2d(std::cos(dir), std::sin(dir));
  g.base_height = -g.slope.dot(spec.center);  // height 0 at the scene centre
  g.bump_amplitude = spec.bump_amplitude_m;
  g.bump_spacing = spec.bump_spacing_m;
  return Ground(g, rng.bits());
}

SceneContent generateScene(const SceneSpec& spec, std::uint64_t seed, Ground ground,
                           const std::vector<Eigen::Vector2d>& path) {
  SceneContent content;
  content.ground = std::move(ground);
  Rng rng(hashKeys(seed, 0x6c61796f7574ULL));  // "layout"
  ObjectBuilder build(content, rng);
  detail::Placer place(path, spec.clearance_m);
  if (spec.layout == "parking-lot")
    detail::layoutParkingLot(spec, build, place, rng);
  else if (spec.layout == "street")
    detail::layoutStreet(spec, build, place, rng);
  else if (spec.layout == "container-yard")
    detail::layoutContainerYard(spec, build, content, place, rng);
  else if (spec.layout == "calibration-bay")
    detail::layoutCalibrationBay(spec, build, place, rng, content);
  else if (spec.layout == "bay-one-wall")
    detail::layoutBayOneWall(spec, build, place, rng, content);
  else if (spec.layout != "empty")
    throw std::invalid_argument("unknown scene layout '" + spec.layout +
                                "'; known: parking-lot, street, container-yard, empty, calibration-bay, bay-one-wall");
  return content;
}

}  // namespace rigcal::sim
