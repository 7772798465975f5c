#include "rigcal/sim/scene_objects.hpp"

#include <algorithm>
#include <cmath>

namespace rigcal::sim {
namespace {

Eigen::Vector2d along(double yaw) { return {std::cos(yaw), std::sin(yaw)}; }
Eigen::Vector2d across(double yaw) { return {-std::sin(yaw), std::cos(yaw)}; }

}  // namespace

Rect2 rotatedRect(Eigen::Vector2d center, double yaw, double length, double width) {
  return footprint(Box::make(center.x(), center.y(), yaw, length, width, 0, 1, Material::kConcrete));
}

double ObjectBuilder::groundBelow(const Rect2& r) const {
  const Ground& g = c_.ground;
  return std::min({g.height(r.x0, r.y0), g.height(r.x1, r.y0), g.height(r.x0, r.y1), g.height(r.x1, r.y1),
                   g.height(0.5 * (r.x0 + r.x1), 0.5 * (r.y0 + r.y1))}) -
         0.15;
}

void ObjectBuilder::facade(const Box& core, double recess, double floor_height, int floors, Material m) {
  // Pillars and floor bands stand `recess` proud of the glass core on all four sides, leaving the
  // windows as recesses: strong, repeated vertical and horizontal edges, as real facades have.
  const double yaw = std::atan2(core.sin_yaw, core.cos_yaw);
  const double z0 = core.z0, top = core.z1;
  for (int side = 0; side < 4; ++side) {
    const bool long_side = side % 2 == 0;
    const double half_len = long_side ? core.hx : core.hy;  // along this face
    const double off = (long_side ? core.hy : core.hx) + 0.5 * recess;
    const double face_yaw = long_side ? yaw : yaw + M_PI_2;
    const double sign = side < 2 ? 1.0 : -1.0;
    const Eigen::Vector2d n = sign * (long_side ? across(yaw) : along(yaw));
    const Eigen::Vector2d c = Eigen::Vector2d(core.cx, core.cy) + off * n;
    const Eigen::Vector2d t = along(face_yaw);
    const double span = 2 * half_len + 2 * recess;
    const int bays = std::max(1, int(std::round(span / rng_.uniform(2.4, 3.6))));
    const double bay = span / bays;
    // Pillars at every bay boundary (0.5 m wide), full height plus parapet.
    for (int k = 0; k <= bays; ++k) {
      const Eigen::Vector2d p = c + (-0.5 * span + k * bay) * t;
      const double w = (k == 0 || k == bays) ? 0.8 : 0.5;
      c_.boxes.push_back(Box::make(p.x(), p.y(), face_yaw, w, recess, z0, top + 0.6, m));
    }
    // Floor bands (sill to floor); the ground floor band is a plinth.
    for (int f = 0; f < floors; ++f) {
      const double zb = z0 + f * floor_height;
      c_.boxes.push_back(Box::make(c.x(), c.y(), face_yaw, span, recess, zb, zb + (f == 0 ? 0.75 : 1.0), m));
    }
    // Parapet above the roof.
    c_.boxes.push_back(Box::make(c.x(), c.y(), face_yaw, span, recess, top - 0.4, top + 0.6, m));
  }
}

Rect2 ObjectBuilder::building(Eigen::Vector2d center, double yaw, double length, double depth, int floors,
                              bool l_shape) {
  const double recess = 0.25, floor_height = rng_.uniform(3.0, 3.6);
  const Material walls = rng_.chance(0.5) ? Material::kBrick : Material::kPlaster;
  const Rect2 area = rotatedRect(center, yaw, length, depth);
  const double z0 = groundBelow(area) - 0.2, top = z0 + 0.2 + floors * floor_height;
  const auto block = [&](Eigen::Vector2d c, double len, double dep, double height) {
    const Box core = Box::make(c.x(), c.y(), yaw, len - 2 * recess, dep - 2 * recess, z0, height, Material::kGlass);
    c_.boxes.push_back(core);
    facade(core, recess, floor_height, int((height - z0) / floor_height + 0.5), walls);
    // A flat roof slab (concrete) just below the parapet top.
    c_.boxes.push_back(Box::make(c.x(), c.y(), yaw, len - 2 * recess, dep - 2 * recess, height - 0.3, height,
                                 Material::kConcrete));
  };
  block(center, length, depth, top);
  Rect2 fp = area;
  if (l_shape) {
    // A lower wing at one end, projecting from the back: an inside corner and a second roof level.
    const double wing_len = length * rng_.uniform(0.3, 0.45), wing_dep = depth * rng_.uniform(0.6, 1.0);
    const double end = rng_.chance(0.5) ? 1.0 : -1.0;
    const Eigen::Vector2d c = center + end * (0.5 * length - 0.5 * wing_len) * along(yaw) -
                              (0.5 * depth + 0.5 * wing_dep - 0.01) * across(yaw);
    const int wing_floors = std::max(1, floors - 1);
    block(c, wing_len, wing_dep, z0 + 0.2 + wing_floors * floor_height);
    const Rect2 w = rotatedRect(c, yaw, wing_len, wing_dep);
    fp = {std::min(fp.x0, w.x0), std::min(fp.y0, w.y0), std::max(fp.x1, w.x1), std::max(fp.y1, w.y1)};
  }
  // An entrance canopy over the front door.
  const Eigen::Vector2d door = center + rng_.uniform(-0.3, 0.3) * length * along(yaw) + (0.5 * depth + 0.8) * across(yaw);
  c_.boxes.push_back(Box::make(door.x(), door.y(), yaw, 3.0, 1.6, z0 + 3.0, z0 + 3.25, Material::kConcrete));
  return fp;
}

Rect2 ObjectBuilder::car(Eigen::Vector2d center, double yaw) {
  const double length = rng_.uniform(4.0, 4.9), width = rng_.uniform(1.7, 1.9);
  const bool van = rng_.chance(0.15);
  const Rect2 fp = rotatedRect(center, yaw, length, width);
  const double g = groundBelow(fp) + 0.15;  // wheels stand on the ground
  const Material paint = Material::kCarPaint;
  // Body (lifted off the ground: rays pass underneath to the wheels and the ground behind).
  c_.boxes.push_back(Box::make(center.x(), center.y(), yaw, length, width, g + 0.3, g + (van ? 1.2 : 0.95), paint));
  // Cabin: glass, set back from the front; van cabins are tall and long.
  const double cab_len = van ? length * 0.75 : length * rng_.uniform(0.45, 0.55);
  const Eigen::Vector2d cab = center - (van ? 0.1 : 0.25) * length * 0.3 * along(yaw);
  const double cab_top = g + (van ? 2.0 : rng_.uniform(1.38, 1.5));
  c_.boxes.push_back(Box::make(cab.x(), cab.y(), yaw, cab_len, width - 0.15, g + (van ? 1.2 : 0.95),
                               cab_top - 0.06, Material::kGlass));
  c_.boxes.push_back(Box::make(cab.x(), cab.y(), yaw, cab_len - 0.2, width - 0.2, cab_top - 0.06, cab_top, paint));
  // Wheels.
  for (int i = 0; i < 4; ++i) {
    const double ax = (i < 2 ? 0.5 : -0.5) * (length - 1.4), ay = (i % 2 ? 0.5 : -0.5) * (width - 0.25);
    const Eigen::Vector2d w = center + ax * along(yaw) + ay * across(yaw);
    c_.boxes.push_back(Box::make(w.x(), w.y(), yaw, 0.66, 0.22, g - 0.1, g + 0.55, Material::kTyre));
  }
  return fp;
}

Rect2 ObjectBuilder::tree(Eigen::Vector2d at) {
  const double trunk_r = rng_.uniform(0.12, 0.3), trunk_h = rng_.uniform(1.8, 3.2);
  const double crown_r = rng_.uniform(1.4, 3.0), crown_rz = crown_r * rng_.uniform(0.9, 1.5);
  const double g = c_.ground.height(at.x(), at.y()) - 0.2;
  c_.cylinders.push_back({at.x(), at.y(), trunk_r, g, g + trunk_h + crown_rz, Material::kBark});
  c_.ellipsoids.push_back({at.x(), at.y(), g + trunk_h + 0.8 * crown_rz, crown_r, crown_rz, Material::kFoliage});
  return {at.x() - crown_r, at.y() - crown_r, at.x() + crown_r, at.y() + crown_r};
}

Rect2 ObjectBuilder::lightPole(Eigen::Vector2d at, double arm_yaw) {
  const double h = rng_.uniform(6.0, 9.0), r = rng_.uniform(0.07, 0.12);
  const double g = c_.ground.height(at.x(), at.y()) - 0.2;
  c_.cylinders.push_back({at.x(), at.y(), r + 0.08, g, g + 0.9, Material::kConcrete});  // foundation
  c_.cylinders.push_back({at.x(), at.y(), r, g, g + h, Material::kMetal});
  const double arm = rng_.uniform(1.2, 2.2);
  const Eigen::Vector2d mid = at + 0.5 * arm * along(arm_yaw);
  c_.boxes.push_back(Box::make(mid.x(), mid.y(), arm_yaw, arm, 0.12, g + h - 0.25, g + h - 0.1, Material::kMetal));
  const Eigen::Vector2d lamp = at + arm * along(arm_yaw);
  c_.boxes.push_back(Box::make(lamp.x(), lamp.y(), arm_yaw, 0.7, 0.3, g + h - 0.45, g + h - 0.2, Material::kMetal));
  return {at.x() - arm - 0.4, at.y() - arm - 0.4, at.x() + arm + 0.4, at.y() + arm + 0.4};
}

Rect2 ObjectBuilder::sign(Eigen::Vector2d at, double yaw) {
  const double g = c_.ground.height(at.x(), at.y()) - 0.2;
  c_.cylinders.push_back({at.x(), at.y(), 0.035, g, g + 2.6, Material::kMetal});
  const Eigen::Vector2d plate = at + 0.06 * along(yaw);
  c_.boxes.push_back(Box::make(plate.x(), plate.y(), yaw, 0.04, 0.65, g + 2.0, g + 2.65, Material::kRetroReflector));
  return {at.x() - 0.4, at.y() - 0.4, at.x() + 0.4, at.y() + 0.4};
}

Rect2 ObjectBuilder::bollard(Eigen::Vector2d at) {
  const double g = c_.ground.height(at.x(), at.y()) - 0.2;
  const double h = rng_.uniform(0.9, 1.2);
  c_.cylinders.push_back({at.x(), at.y(), rng_.uniform(0.08, 0.13), g, g + h,
                          rng_.chance(0.5) ? Material::kMetal : Material::kConcrete});
  return {at.x() - 0.2, at.y() - 0.2, at.x() + 0.2, at.y() + 0.2};
}

Rect2 ObjectBuilder::wall(Eigen::Vector2d a, Eigen::Vector2d b, double height, double thickness, Material m) {
  const Eigen::Vector2d c = 0.5 * (a + b);
  const double yaw = std::atan2(b.y() - a.y(), b.x() - a.x()), len = (b - a).norm();
  const Rect2 fp = rotatedRect(c, yaw, len, thickness);
  const double z0 = groundBelow(fp);
  c_.boxes.push_back(Box::make(c.x(), c.y(), yaw, len, thickness, z0, z0 + 0.15 + height, m));
  // A coping on top, slightly wider: a horizontal edge the mapper can lock onto.
  c_.boxes.push_back(Box::make(c.x(), c.y(), yaw, len, thickness + 0.1, z0 + 0.15 + height,
                               z0 + 0.25 + height, Material::kConcrete));
  return fp;
}

Rect2 ObjectBuilder::curb(Eigen::Vector2d a, Eigen::Vector2d b) {
  const Eigen::Vector2d c = 0.5 * (a + b);
  const double yaw = std::atan2(b.y() - a.y(), b.x() - a.x()), len = (b - a).norm();
  const Rect2 fp = rotatedRect(c, yaw, len, 0.25);
  // Follows the ground along its length: split into ~3 m stones so a slope does not bury or lift it.
  const int pieces = std::max(1, int(std::ceil(len / 3.0)));
  for (int i = 0; i < pieces; ++i) {
    const Eigen::Vector2d p = a + (i + 0.5) / pieces * (b - a);
    const double g = c_.ground.height(p.x(), p.y());
    c_.boxes.push_back(Box::make(p.x(), p.y(), yaw, len / pieces, 0.25, g - 0.3, g + 0.15, Material::kCurbStone));
  }
  return fp;
}

Rect2 ObjectBuilder::island(Eigen::Vector2d center, double yaw, double length, double width) {
  const Eigen::Vector2d u = 0.5 * (length - 0.25) * along(yaw), v = 0.5 * (width - 0.25) * across(yaw);
  curb(center - u - v, center + u - v);
  curb(center - u + v, center + u + v);
  curb(center - u - v + 0.125 * along(yaw), center - u + v + 0.125 * along(yaw));
  curb(center + u - v - 0.125 * along(yaw), center + u + v - 0.125 * along(yaw));
  const Rect2 fp = rotatedRect(center, yaw, length, width);
  const double g = c_.ground.height(center.x(), center.y());
  // The planted top sits just under the curb top.
  c_.boxes.push_back(Box::make(center.x(), center.y(), yaw, length - 0.5, width - 0.5, groundBelow(fp) - 0.1,
                               g + 0.1, Material::kGrass));
  return fp;
}

void ObjectBuilder::paint(Eigen::Vector2d center, double yaw, double length, double width, Material m) {
  c_.patches.push_back(Box::make(center.x(), center.y(), yaw, length, width, 0, 0, m));
}

}  // namespace rigcal::sim
