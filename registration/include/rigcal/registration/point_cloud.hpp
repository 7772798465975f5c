#pragma once
// The registration layer's point cloud. Positions are homogeneous Eigen::Vector4d (w = 1) so a Pose applies
// as one vectorised 4x4 product; normals (w = 0) and covariances (last row/column zero) are optional and
// filled by covariance.hpp when a method needs them.
#include <cstddef>
#include <span>
#include <vector>

#include <Eigen/Core>

#include "rigcal/core/point_table.hpp"
#include "rigcal/core/pose.hpp"
#include "rigcal/core/scan.hpp"

namespace rigcal::registration {

struct PointCloud {
  std::vector<Eigen::Vector4d> points;
  std::vector<Eigen::Vector4d> normals;      // empty, or one unit normal per point (zero = unknown)
  std::vector<Eigen::Matrix4d> covariances;  // empty, or one per point

  [[nodiscard]] std::size_t size() const { return points.size(); }
  [[nodiscard]] bool empty() const { return points.empty(); }
  [[nodiscard]] bool hasNormals() const { return !points.empty() && normals.size() == points.size(); }
  [[nodiscard]] bool hasCovariances() const {
    return !points.empty() && covariances.size() == points.size();
  }
  /// Appends (x, y, z) when all three are finite; returns false (and appends nothing) otherwise.
  bool add(double x, double y, double z);
  /// Drops normals and covariances (after the positions changed).
  void clearAttributes();
};

/// The finite points of a scan, table (needs x, y, z) or vector; `dropped` (optional) counts the others.
PointCloud fromScan(const Scan& scan, std::size_t* dropped = nullptr);
PointCloud fromTable(const PointTable& table, std::size_t* dropped = nullptr);
PointCloud fromPoints(std::span<const Eigen::Vector3d> points, std::size_t* dropped = nullptr);

/// The way back: a scan of the cloud's positions (as float) with `like`'s sensor_id, sequence and stamp_ns;
/// every other field zero (all points at the stamp).
Scan toScan(const PointCloud& cloud, const Scan& like);

/// A copy with positions, normals and covariances mapped by T_to_from.
PointCloud transformed(const PointCloud& cloud, const Pose& T_to_from);

/// True when every position (and normal and covariance present) is finite.
bool allFinite(const PointCloud& cloud);

}  // namespace rigcal::registration
