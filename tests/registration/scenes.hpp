#pragma once
// Test scenes: synthetic surfaces (a furnished room, a plane, a corridor) and real reference scans moved
// by a known transform with noise.
#include <cstddef>
#include <filesystem>
#include <random>

#include "rigcal/core/pcd_io.hpp"
#include "rigcal/core/pose.hpp"
#include "rigcal/registration/point_cloud.hpp"

namespace rigcal::registration::test {

/// Points on an axis-aligned box's surface patch x∈[x0,x1], y∈[y0,y1], z∈[z0,z1] (one extent zero).
inline void addPatch(PointCloud& c, Eigen::Vector3d lo, Eigen::Vector3d hi, double step) {
  for (double x = lo.x(); x <= hi.x() + 1e-9; x += (hi.x() > lo.x() ? step : 1.0)) {
    for (double y = lo.y(); y <= hi.y() + 1e-9; y += (hi.y() > lo.y() ? step : 1.0)) {
      for (double z = lo.z(); z <= hi.z() + 1e-9; z += (hi.z() > lo.z() ? step : 1.0)) c.add(x, y, z);
    }
  }
}

inline PointCloud roomAtOrigin(double step) {
  PointCloud c;
  addPatch(c, {-5, -4, 0}, {5, 4, 0}, step);     // floor
  addPatch(c, {-5, -4, 3}, {5, 4, 3}, step);     // ceiling
  addPatch(c, {-5, -4, 0}, {-5, 4, 3}, step);    // walls
  addPatch(c, {5, -4, 0}, {5, 4, 3}, step);
  addPatch(c, {-5, -4, 0}, {5, -4, 3}, step);
  addPatch(c, {-5, 4, 0}, {5, 4, 3}, step);
  addPatch(c, {1, 1, 0}, {1, 1.6, 3}, step);     // pillar faces
  addPatch(c, {1.6, 1, 0}, {1.6, 1.6, 3}, step);
  addPatch(c, {1, 1, 0}, {1.6, 1, 3}, step);
  addPatch(c, {-3, -2, 0}, {-3, -1, 1.2}, step); // cabinet
  addPatch(c, {-3, -2, 1.2}, {-2, -1, 1.2}, step);
  for (double u = 0; u <= 2.0; u += step) {       // panel leaning on the east wall
    for (double z = 0; z <= 2.0; z += step) c.add(4.0 + 0.4 * z, -2.0 + u, z);
  }
  return c;
}

/// A 10 x 8 x 3 m room with a pillar, a cabinet and a slanted panel, so all six DOF are observable.
/// Its walls are kept off round coordinates: walls lying exactly on NDT voxel faces are a pathology of
/// the synthetic scene, not something a real scan shows.
inline PointCloud room(double step = 0.15) {
  PointCloud c = roomAtOrigin(step);
  for (auto& p : c.points) p.head<3>() += Eigen::Vector3d(0.31, 0.17, 0.23);
  return c;
}

inline PointCloud plane(double step = 0.1) {
  PointCloud c;
  addPatch(c, {-10, -10, 0}, {10, 10, 0}, step);
  return c;
}

/// A 30 m corridor along x: nothing constrains translation along it.
inline PointCloud corridor(double step = 0.1) {
  PointCloud c;
  addPatch(c, {0, -1.5, 0}, {30, 1.5, 0}, step);
  addPatch(c, {0, -1.5, 2.5}, {30, 1.5, 2.5}, step);
  addPatch(c, {0, -1.5, 0}, {30, -1.5, 2.5}, step);
  addPatch(c, {0, 1.5, 0}, {30, 1.5, 2.5}, step);
  return c;
}

/// T_source_target·p + N(0, sigma²) per axis for every `stride`-th point starting at `first`: a source
/// cloud for which T_target_source is the ground truth.
inline PointCloud movedCopy(const PointCloud& target, const Pose& T_target_source, double sigma,
                            std::size_t stride = 1, std::size_t first = 0, unsigned seed = 7) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, sigma);
  const Eigen::Matrix4d M = T_target_source.inverse().matrix();
  PointCloud out;
  for (std::size_t i = first; i < target.size(); i += stride) {
    Eigen::Vector4d p = M * target.points[i];
    if (sigma > 0.0) p.head<3>() += Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
    out.points.push_back(p);
  }
  return out;
}

/// The points of a reference PCD within max_range of the sensor.
inline PointCloud loadScan(const std::filesystem::path& path, double max_range = 1e9) {
  const PointCloud all = fromTable(readPcd(path));
  PointCloud out;
  for (const auto& p : all.points) {
    if (p.head<3>().norm() < max_range) out.points.push_back(p);
  }
  return out;
}

inline double translationError(const Pose& estimate, const Pose& truth) {
  return (truth.inverse() * estimate).translation().norm();
}
inline double rotationErrorDeg(const Pose& estimate, const Pose& truth) {
  return rad2deg(rotationAngle(truth.inverse() * estimate));
}

/// The offset every known-transform test starts from: 0.36 m and about 3.2 degrees.
inline Pose knownTransform() { return fromXyzRpy({0.3, -0.2, 0.05, deg2rad(1.0), deg2rad(-0.5), deg2rad(3.0)}); }

}  // namespace rigcal::registration::test
