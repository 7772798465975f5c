#pragma once
// Scene primitives, all with a vertical axis (the world is built upright): oriented boxes (buildings,
// walls, curbs, car bodies), vertical cylinders (poles, trunks, bollards) and vertical-axis ellipsoids
// (tree crowns). Intersections are inline: the ray caster calls them hundreds of millions of times.
#include <cmath>
#include <limits>

#include <Eigen/Core>

#include "rigcal/sim/material.hpp"

namespace rigcal::sim {

struct Ray {
  Eigen::Vector3d origin;
  Eigen::Vector3d dir;  // unit length
};

struct Hit {
  double t = std::numeric_limits<double>::infinity();  // distance along the ray
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // world frame, unit
  Material material = Material::kAsphalt;
  [[nodiscard]] bool found() const { return std::isfinite(t); }
};

/// Axis-aligned rectangle in the ground plane (a primitive's footprint).
struct Rect2 {
  double x0, y0, x1, y1;
};

/// Box rotated by `yaw` about the vertical axis: |local x| ≤ hx, |local y| ≤ hy, z in [z0, z1].
struct Box {
  double cx = 0, cy = 0, cos_yaw = 1, sin_yaw = 0, hx = 0.5, hy = 0.5, z0 = 0, z1 = 1;
  Material material = Material::kConcrete;

  static Box make(double cx, double cy, double yaw, double length, double width, double z0, double z1,
                  Material m) {
    return {cx, cy, std::cos(yaw), std::sin(yaw), 0.5 * length, 0.5 * width, z0, z1, m};
  }
};

struct Cylinder {
  double cx = 0, cy = 0, radius = 0.1, z0 = 0, z1 = 1;
  Material material = Material::kMetal;
};

/// Ellipsoid with horizontal radius `r` and vertical radius `rz`, centred at (cx, cy, cz).
struct Ellipsoid {
  double cx = 0, cy = 0, cz = 0, r = 1, rz = 1;
  Material material = Material::kFoliage;
};

Rect2 footprint(const Box& b);
Rect2 footprint(const Cylinder& c);
Rect2 footprint(const Ellipsoid& e);

/// Unsigned distance from p to the primitive's surface (exact for boxes and cylinders; first-order
/// for ellipsoids, exact on the surface).
double surfaceDistance(const Box& b, const Eigen::Vector3d& p);
double surfaceDistance(const Cylinder& c, const Eigen::Vector3d& p);
double surfaceDistance(const Ellipsoid& e, const Eigen::Vector3d& p);

// Each intersect() updates `hit` only when it finds a surface nearer than hit.t (and beyond t_min).
// Rays that start inside a solid see no hit from it: sensors are always outside.

inline bool intersect(const Box& b, const Ray& ray, double t_min, Hit& hit) {
  const double px = ray.origin.x() - b.cx, py = ray.origin.y() - b.cy;
  const double ox = b.cos_yaw * px + b.sin_yaw * py, oy = -b.sin_yaw * px + b.cos_yaw * py;
  const double dx = b.cos_yaw * ray.dir.x() + b.sin_yaw * ray.dir.y();
  const double dy = -b.sin_yaw * ray.dir.x() + b.cos_yaw * ray.dir.y();
  const double dz = ray.dir.z(), oz = ray.origin.z();
  double t_near = -std::numeric_limits<double>::infinity(), t_far = hit.t;
  int axis = -1;
  double sign = 0;
  // Slabs; a zero direction component is handled by the infinities IEEE division gives.
  const auto slab = [&](double o, double d, double lo, double hi, int a) {
    const double inv = 1.0 / d;
    double t0 = (lo - o) * inv, t1 = (hi - o) * inv;
    double s = -1;
    if (t0 > t1) {
      std::swap(t0, t1);
      s = 1;
    }
    if (t0 > t_near) {
      t_near = t0;
      axis = a;
      sign = s;
    }
    if (t1 < t_far) t_far = t1;
  };
  if (dx == 0 && (ox < -b.hx || ox > b.hx)) return false;
  if (dy == 0 && (oy < -b.hy || oy > b.hy)) return false;
  if (dz == 0 && (oz < b.z0 || oz > b.z1)) return false;
  if (dx != 0) slab(ox, dx, -b.hx, b.hx, 0);
  if (dy != 0) slab(oy, dy, -b.hy, b.hy, 1);
  if (dz != 0) slab(oz, dz, b.z0, b.z1, 2);
  if (axis < 0 || t_near > t_far || t_near < t_min || t_near >= hit.t) return false;
  hit.t = t_near;
  hit.material = b.material;
  if (axis == 0)
    hit.normal = {sign * b.cos_yaw, sign * b.sin_yaw, 0};
  else if (axis == 1)
    hit.normal = {-sign * b.sin_yaw, sign * b.cos_yaw, 0};
  else
    hit.normal = {0, 0, sign};
  return true;
}

inline bool intersect(const Cylinder& c, const Ray& ray, double t_min, Hit& hit) {
  const double px = ray.origin.x() - c.cx, py = ray.origin.y() - c.cy;
  const double dx = ray.dir.x(), dy = ray.dir.y(), dz = ray.dir.z(), oz = ray.origin.z();
  const double r2 = c.radius * c.radius;
  bool found = false;
  const double a = dx * dx + dy * dy;
  if (a > 1e-18) {
    const double b = px * dx + py * dy;
    const double cc = px * px + py * py - r2;
    const double disc = b * b - a * cc;
    if (disc >= 0 && cc > 0) {  // cc > 0: origin outside the cylinder
      const double t = (-b - std::sqrt(disc)) / a;
      const double z = oz + t * dz;
      if (t >= t_min && t < hit.t && z >= c.z0 && z <= c.z1) {
        hit.t = t;
        hit.material = c.material;
        hit.normal = {(px + t * dx) / c.radius, (py + t * dy) / c.radius, 0};
        found = true;
      }
    }
  }
  if (dz < 0 && oz > c.z1) {  // top cap, seen from above
    const double t = (c.z1 - oz) / dz;
    const double x = px + t * dx, y = py + t * dy;
    if (t >= t_min && t < hit.t && x * x + y * y <= r2) {
      hit.t = t;
      hit.material = c.material;
      hit.normal = {0, 0, 1};
      found = true;
    }
  }
  return found;
}

inline bool intersect(const Ellipsoid& e, const Ray& ray, double t_min, Hit& hit) {
  // Scale z by r/rz: the ellipsoid becomes a sphere of radius r; t is unchanged by the scaling.
  const double k = e.r / e.rz;
  const double px = ray.origin.x() - e.cx, py = ray.origin.y() - e.cy, pz = (ray.origin.z() - e.cz) * k;
  const double dx = ray.dir.x(), dy = ray.dir.y(), dz = ray.dir.z() * k;
  const double a = dx * dx + dy * dy + dz * dz;
  const double b = px * dx + py * dy + pz * dz;
  const double cc = px * px + py * py + pz * pz - e.r * e.r;
  const double disc = b * b - a * cc;
  if (disc < 0 || cc <= 0) return false;
  const double t = (-b - std::sqrt(disc)) / a;
  if (t < t_min || t >= hit.t) return false;
  hit.t = t;
  hit.material = e.material;
  // Gradient of x² + y² + (k z)² at the hit, back in world scale.
  const Eigen::Vector3d g(px + t * dx, py + t * dy, (pz + t * dz) * k);
  hit.normal = g.normalized();
  return true;
}

}  // namespace rigcal::sim
