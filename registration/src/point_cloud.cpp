#include "rigcal/registration/point_cloud.hpp"

#include <cmath>

namespace rigcal::registration {

bool PointCloud::add(double x, double y, double z) {
  if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z)) return false;
  points.emplace_back(x, y, z, 1.0);
  return true;
}

void PointCloud::clearAttributes() {
  normals.clear();
  covariances.clear();
}

PointCloud fromScan(const Scan& scan, std::size_t* dropped) {
  PointCloud cloud;
  cloud.points.reserve(scan.size());
  std::size_t bad = 0;
  for (std::size_t i = 0; i < scan.size(); ++i) {
    if (!cloud.add(scan.x[i], scan.y[i], scan.z[i])) ++bad;
  }
  if (dropped) *dropped = bad;
  return cloud;
}

PointCloud fromTable(const PointTable& table, std::size_t* dropped) {
  const auto& x = table.column("x");
  const auto& y = table.column("y");
  const auto& z = table.column("z");
  PointCloud cloud;
  cloud.points.reserve(x.size());
  std::size_t bad = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (!cloud.add(x[i], y[i], z[i])) ++bad;
  }
  if (dropped) *dropped = bad;
  return cloud;
}

PointCloud fromPoints(std::span<const Eigen::Vector3d> points, std::size_t* dropped) {
  PointCloud cloud;
  cloud.points.reserve(points.size());
  std::size_t bad = 0;
  for (const auto& p : points) {
    if (!cloud.add(p.x(), p.y(), p.z())) ++bad;
  }
  if (dropped) *dropped = bad;
  return cloud;
}

Scan toScan(const PointCloud& cloud, const Scan& like) {
  Scan s;
  s.sensor_id = like.sensor_id;
  s.sequence = like.sequence;
  s.stamp_ns = like.stamp_ns;
  s.reserve(cloud.size());
  for (const auto& p : cloud.points) {
    s.x.push_back(float(p.x()));
    s.y.push_back(float(p.y()));
    s.z.push_back(float(p.z()));
  }
  s.intensity.assign(s.size(), 0.0f);
  s.ring.assign(s.size(), 0);
  s.offset_ns.assign(s.size(), 0);
  s.return_index.assign(s.size(), 0);
  return s;
}

PointCloud transformed(const PointCloud& cloud, const Pose& T_to_from) {
  const Eigen::Matrix4d M = T_to_from.matrix();
  PointCloud out;
  out.points.resize(cloud.points.size());
  for (std::size_t i = 0; i < cloud.points.size(); ++i) out.points[i] = M * cloud.points[i];
  if (cloud.hasNormals()) {
    out.normals.resize(cloud.normals.size());
    for (std::size_t i = 0; i < cloud.normals.size(); ++i) out.normals[i] = M * cloud.normals[i];
  }
  if (cloud.hasCovariances()) {
    out.covariances.resize(cloud.covariances.size());
    for (std::size_t i = 0; i < cloud.covariances.size(); ++i) {
      out.covariances[i] = M * cloud.covariances[i] * M.transpose();
    }
  }
  return out;
}

bool allFinite(const PointCloud& cloud) {
  for (const auto& p : cloud.points) {
    if (!p.allFinite()) return false;
  }
  for (const auto& n : cloud.normals) {
    if (!n.allFinite()) return false;
  }
  for (const auto& c : cloud.covariances) {
    if (!c.allFinite()) return false;
  }
  return true;
}

}  // namespace rigcal::registration
