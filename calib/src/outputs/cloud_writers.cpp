#include "rigcal/calib/outputs/cloud_writers.hpp"

#include <set>

#include "rigcal/core/pcd_io.hpp"
#include "rigcal/core/point_table.hpp"
#include "rigcal/registration/voxel_grid.hpp"

namespace rigcal::calib {

std::vector<Eigen::Vector3d> mapCloud(const std::vector<pipeline::CalibrationDataset>& datasets, double leaf) {
  registration::PointCloud all;
  std::set<std::uint64_t> seen;
  for (const auto& d : datasets)
    for (const auto& mc : d.mapping_clouds) {
      if (mc.cloud == nullptr || !seen.insert(mc.frame.sequence).second) continue;
      const Scan& s = *mc.cloud;
      for (std::size_t i = 0; i < s.size(); ++i) {
        const Eigen::Vector3d p = mc.frame.T_map_lidar * Eigen::Vector3d(s.x[i], s.y[i], s.z[i]);
        all.add(p.x(), p.y(), p.z());
      }
    }
  if (!all.empty() && leaf > 0) all = registration::voxelDownsample(all, leaf);
  std::vector<Eigen::Vector3d> out;
  out.reserve(all.size());
  for (const auto& p : all.points) out.push_back(p.head<3>());
  return out;
}

std::vector<Eigen::Vector3d> outcomeMapCloud(const CalibrationOutcome& outcome, double leaf) {
  if (outcome.map_cloud == nullptr) return mapCloud(outcome.datasets, leaf);
  const Scan& s = *outcome.map_cloud;
  std::vector<Eigen::Vector3d> out;
  out.reserve(s.size());
  for (std::size_t i = 0; i < s.size(); ++i) out.emplace_back(s.x[i], s.y[i], s.z[i]);
  return out;
}

std::vector<Eigen::Vector3d> calibrationCloudInMap(const pipeline::CalibrationDataset& dataset,
                                                   const Pose& T_mapping_calib) {
  std::vector<Eigen::Vector3d> out;
  for (const auto& f : dataset.frames) {
    if (f.deskewed == nullptr) continue;
    const Pose T = f.pairing.T_map_mapping_at_scan * T_mapping_calib;
    const Scan& s = *f.deskewed;
    for (std::size_t i = 0; i < s.size(); ++i) {
      const Eigen::Vector3d p = T * Eigen::Vector3d(s.x[i], s.y[i], s.z[i]);
      if (p.allFinite()) out.push_back(p);
    }
  }
  return out;
}

void writeCloudPcd(const std::filesystem::path& path, const std::vector<Eigen::Vector3d>& points) {
  std::vector<double> x, y, z;
  x.reserve(points.size());
  y.reserve(points.size());
  z.reserve(points.size());
  for (const auto& p : points) {
    x.push_back(p.x());
    y.push_back(p.y());
    z.push_back(p.z());
  }
  PointTable table;
  table.add("x", FieldType::kF32, std::move(x));
  table.add("y", FieldType::kF32, std::move(y));
  table.add("z", FieldType::kF32, std::move(z));
  writePcd(path, table, PcdEncoding::kBinary);
}

void writeCalibrationClouds(const std::filesystem::path& dir, const CalibrationOutcome& outcome, double map_leaf) {
  writeCloudPcd(dir / "map.pcd", outcomeMapCloud(outcome, map_leaf));
  for (const auto& d : outcome.datasets) {
    writeCloudPcd(dir / (d.calibration_sensor + "_before.pcd"), calibrationCloudInMap(d, d.T_mapping_calib_guess));
    const LidarLidarResult* r = outcome.lidar(d.calibration_sensor);
    const Pose after = (r != nullptr && r->ok) ? r->T_mapping_calib : d.T_mapping_calib_guess;
    writeCloudPcd(dir / (d.calibration_sensor + "_after.pcd"), calibrationCloudInMap(d, after));
  }
}

}  // namespace rigcal::calib
