#include "rigcal/sim/primitives.hpp"

#include <algorithm>

namespace rigcal::sim {

Rect2 footprint(const Box& b) {
  const double ex = std::abs(b.cos_yaw) * b.hx + std::abs(b.sin_yaw) * b.hy;
  const double ey = std::abs(b.sin_yaw) * b.hx + std::abs(b.cos_yaw) * b.hy;
  return {b.cx - ex, b.cy - ey, b.cx + ex, b.cy + ey};
}

Rect2 footprint(const Cylinder& c) {
  return {c.cx - c.radius, c.cy - c.radius, c.cx + c.radius, c.cy + c.radius};
}

Rect2 footprint(const Ellipsoid& e) { return {e.cx - e.r, e.cy - e.r, e.cx + e.r, e.cy + e.r}; }

double surfaceDistance(const Box& b, const Eigen::Vector3d& p) {
  const double px = p.x() - b.cx, py = p.y() - b.cy;
  const double lx = b.cos_yaw * px + b.sin_yaw * py, ly = -b.sin_yaw * px + b.cos_yaw * py;
  const double hz = 0.5 * (b.z1 - b.z0), lz = p.z() - 0.5 * (b.z0 + b.z1);
  const Eigen::Vector3d q(std::abs(lx) - b.hx, std::abs(ly) - b.hy, std::abs(lz) - hz);
  const double outside = q.cwiseMax(0.0).norm();
  const double inside = std::min(q.maxCoeff(), 0.0);
  return std::abs(outside + inside);
}

double surfaceDistance(const Cylinder& c, const Eigen::Vector3d& p) {
  const double radial = std::hypot(p.x() - c.cx, p.y() - c.cy) - c.radius;
  const double hz = 0.5 * (c.z1 - c.z0), lz = std::abs(p.z() - 0.5 * (c.z0 + c.z1)) - hz;
  const double outside = std::hypot(std::max(radial, 0.0), std::max(lz, 0.0));
  const double inside = std::min(std::max(radial, lz), 0.0);
  return std::abs(outside + inside);
}

double surfaceDistance(const Ellipsoid& e, const Eigen::Vector3d& p) {
  // F = |q|² − r² with q the z-scaled offset; distance ≈ |F| / |∇F|.
  const double k = e.r / e.rz;
  const Eigen::Vector3d q(p.x() - e.cx, p.y() - e.cy, (p.z() - e.cz) * k);
  const double f = q.squaredNorm() - e.r * e.r;
  const Eigen::Vector3d grad(2 * q.x(), 2 * q.y(), 2 * q.z() * k);
  const double g = grad.norm();
  return g > 1e-12 ? std::abs(f) / g : e.r;
}

}  // namespace rigcal::sim
