// Calibration bays for a parked vehicle (static calibration, `rigcal calibrate --static`):
//  - "calibration-bay": a hall of spec.size around spec.center with walls on all four sides (a door gap in
//    one), stacked crates turned at different yaws, and calibration targets (retro-reflective boards on
//    posts, turned and at several heights) between the vehicle and the walls, so every lidar sees
//    surfaces facing every direction: all six degrees of freedom are constrained.
//  - "bay-one-wall": the degenerate bay, the floor and one flat wall ahead of the vehicle. Translation
//    along the wall and rotation about its normal are not constrained by anything the lidars see.
// Nothing stands within spec.clearance_m of the vehicle (the path is the parked position).
#include <cmath>

#include "scene_layout.hpp"

namespace rigcal::sim::detail {
namespace {

// A board on two posts, its face turned to `yaw`: the lidars' rings cross its edges at several heights.
void target(const Eigen::Vector2d& at, double yaw, double bottom, ObjectBuilder& build, Placer& place,
            SceneContent& content) {
  const double width = 1.2, height = 1.0, thick = 0.04;
  const Rect2 fp = rotatedRect(at, yaw, thick, width);
  if (!place.free(fp, 0.2)) return;
  const double g = build.groundBelow(fp);
  content.boxes.push_back(Box::make(at.x(), at.y(), yaw, thick, width, g + bottom, g + bottom + height,
                                    Material::kRetroReflector));
  const Eigen::Vector2d side(-std::sin(yaw), std::cos(yaw));
  for (const double s : {-0.45, 0.45}) {
    const Eigen::Vector2d p = at + s * width * side - 0.06 * Eigen::Vector2d(std::cos(yaw), std::sin(yaw));
    content.cylinders.push_back({p.x(), p.y(), 0.03, g, g + bottom, Material::kMetal});
  }
  place.occupy(fp);
}

// A crate stack: a base crate and, sometimes, a smaller one on top turned a little.
void crates(const Eigen::Vector2d& at, double yaw, Rng& rng, ObjectBuilder& build, Placer& place,
            SceneContent& content) {
  const double len = rng.uniform(0.8, 1.6), wid = rng.uniform(0.6, 1.2), h = rng.uniform(0.6, 1.4);
  const Rect2 fp = rotatedRect(at, yaw, len, wid);
  if (!place.free(fp, 0.3)) return;
  const double g = build.groundBelow(fp);
  content.boxes.push_back(Box::make(at.x(), at.y(), yaw, len, wid, g, g + h, Material::kPlaster));
  if (rng.chance(0.6)) {
    const double turn = rng.uniform(-0.5, 0.5), h2 = rng.uniform(0.4, 0.8);
    content.boxes.push_back(Box::make(at.x(), at.y(), yaw + turn, 0.6 * len, 0.6 * wid, g + h, g + h + h2,
                                      Material::kMetal));
  }
  place.occupy(fp);
}

}  // namespace

void layoutCalibrationBay(const SceneSpec& spec, ObjectBuilder& build, Placer& place, Rng& rng,
                          SceneContent& content) {
  const Eigen::Vector2d lo = spec.center - 0.5 * spec.size, hi = spec.center + 0.5 * spec.size;
  const double wall_h = 4.0;
  // The four walls; the one behind the vehicle (low x) has a door 4 m wide, off-centre.
  const double door_y = spec.center.y() + 0.2 * spec.size.y();
  build.wall({lo.x(), lo.y()}, {hi.x(), lo.y()}, wall_h, 0.3, Material::kConcrete);
  build.wall({hi.x(), lo.y()}, {hi.x(), hi.y()}, wall_h, 0.3, Material::kBrick);
  build.wall({hi.x(), hi.y()}, {lo.x(), hi.y()}, wall_h, 0.3, Material::kConcrete);
  build.wall({lo.x(), hi.y()}, {lo.x(), door_y + 2.0}, wall_h, 0.3, Material::kPlaster);
  build.wall({lo.x(), door_y - 2.0}, {lo.x(), lo.y()}, wall_h, 0.3, Material::kPlaster);
  // Pillars along the long walls: vertical edges at known spacing.
  for (double x = lo.x() + 3.0; x < hi.x() - 2.0; x += 4.5)
    for (const double y : {lo.y() + 0.45, hi.y() - 0.45}) {
      const Rect2 fp = rotatedRect({x, y}, 0, 0.5, 0.5);
      if (!place.free(fp, 0.0)) continue;
      content.boxes.push_back(Box::make(x, y, 0, 0.5, 0.5, build.groundBelow(fp), wall_h, Material::kConcrete));
      place.occupy(fp);
    }
  // Targets on a ring around the vehicle, each turned a different way and at its own height.
  const int targets = 12;
  const double turn0 = rng.uniform(0, 2 * M_PI);
  for (int k = 0; k < targets; ++k) {
    const double a = turn0 + 2 * M_PI * k / targets, r = rng.uniform(3.5, 5.0);
    const Eigen::Vector2d at = spec.center + r * Eigen::Vector2d(std::cos(a), std::sin(a));
    const double facing = a + M_PI + rng.uniform(-0.7, 0.7);  // roughly towards the vehicle
    target(at, facing, rng.uniform(0.3, 1.4), build, place, content);
  }
  // Crate stacks between the targets and the walls.
  for (int k = 0; k < 24; ++k) {
    const double px = rng.uniform(lo.x() + 1.5, hi.x() - 1.5), py = rng.uniform(lo.y() + 1.5, hi.y() - 1.5);
    const Eigen::Vector2d at(px, py);
    if ((at - spec.center).norm() < spec.clearance_m + 1.5) continue;
    crates(at, rng.uniform(0, M_PI), rng, build, place, content);
  }
}

void layoutBayOneWall(const SceneSpec& spec, ObjectBuilder& build, Placer& /*place*/, Rng& /*rng*/,
                      SceneContent& /*content*/) {
  // One long, flat wall ahead of the vehicle (no coping edge to lock onto along it: plaster, plain).
  const double x = spec.center.x() + 0.5 * spec.size.x();
  build.wall({x, spec.center.y() - 0.5 * spec.size.y()}, {x, spec.center.y() + 0.5 * spec.size.y()}, 4.0, 0.3,
             Material::kPlaster);
}

}  // namespace rigcal::sim::detail
