#pragma once
// Builders for the things a vehicle drives past, each made of primitives standing on the (sloped,
// bumpy) ground: buildings with window recesses, cars, trees, light poles, signs, bollards, walls,
// curbs, raised islands and road paint. Sizes vary with the generator's RNG.
#include <Eigen/Core>

#include "rigcal/sim/random.hpp"
#include "rigcal/sim/scene.hpp"

namespace rigcal::sim {

class ObjectBuilder {
 public:
  ObjectBuilder(SceneContent& content, Rng& rng) : c_(content), rng_(rng) {}

  /// A block building (optionally L-shaped) of `floors` storeys; windows are 0.25 m deep recesses
  /// between facade pillars and floor bands. Returns its footprint.
  Rect2 building(Eigen::Vector2d center, double yaw, double length, double depth, int floors, bool l_shape);
  /// A parked car (body, glass cabin, roof, wheels).
  Rect2 car(Eigen::Vector2d center, double yaw);
  /// A tree: trunk and an ellipsoidal crown.
  Rect2 tree(Eigen::Vector2d at);
  /// A light pole with an arm pointing along `arm_yaw`.
  Rect2 lightPole(Eigen::Vector2d at, double arm_yaw);
  /// A road sign: post and a retro-reflective plate facing `yaw`.
  Rect2 sign(Eigen::Vector2d at, double yaw);
  Rect2 bollard(Eigen::Vector2d at);
  /// A straight wall from a to b.
  Rect2 wall(Eigen::Vector2d a, Eigen::Vector2d b, double height, double thickness, Material m);
  /// A curb stone line from a to b (0.15 m high).
  Rect2 curb(Eigen::Vector2d a, Eigen::Vector2d b);
  /// A raised island: a slab with curbs all round, grass on top.
  Rect2 island(Eigen::Vector2d center, double yaw, double length, double width);
  /// A painted stripe on the ground.
  void paint(Eigen::Vector2d center, double yaw, double length, double width, Material m = Material::kRoadPaint);

  /// Lowest ground height over a footprint (objects are sunk to it so no gap shows on slopes).
  [[nodiscard]] double groundBelow(const Rect2& r) const;

 private:
  void facade(const Box& core, double recess, double floor_height, int floors, Material m);

  SceneContent& c_;
  Rng& rng_;
};

/// Axis-aligned bounds of a rotated rectangle.
Rect2 rotatedRect(Eigen::Vector2d center, double yaw, double length, double width);

}  // namespace rigcal::sim
