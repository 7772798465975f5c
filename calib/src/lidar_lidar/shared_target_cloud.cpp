#include "rigcal/calib/lidar_lidar/shared_target_cloud.hpp"

#include "rigcal/calib/lidar_lidar/augmented_target.hpp"
#include "rigcal/calib/lidar_lidar/source_neighbourhood.hpp"

namespace rigcal::calib {

SharedTargetCloud::SharedTargetCloud(const pipeline::CalibrationDataset& dataset, const config::Parameters& params,
                                     std::size_t max_clouds)
    : dataset_(dataset), params_(params), max_clouds_(max_clouds), voxels_(params.leaf_size_dense_map) {}

Pose SharedTargetCloud::anchor(std::size_t frame) const {
  return dataset_.frames.at(frame).pairing.T_map_mapping_at_scan;
}

bool SharedTargetCloud::add(std::size_t frame, const registration::PointCloud& source, const std::vector<Pose>& poses,
                            double radius, const registration::Deadline& deadline) {
  const Pose T_map_scan = anchor(frame);
  std::vector<Pose> in_map;
  for (const Pose& T : poses) in_map.push_back(T_map_scan * T);
  const SourceNeighbourhood near(source, in_map, radius);
  std::vector<Eigen::Vector4d> cropped;
  for (const std::size_t i : targetWindow(dataset_, frame, params_, max_clouds_)) {
    if (deadline.expired()) return false;
    const auto& mc = dataset_.mapping_clouds[i];
    const Scan& s = *mc.cloud;
    std::vector<bool>& taken = taken_[i];
    taken.resize(s.size(), false);
    const Eigen::Matrix4f T = mc.frame.T_map_lidar.matrix().cast<float>();
    cropped.clear();
    for (std::size_t j = 0; j < s.size(); ++j) {
      if (taken[j]) continue;
      const Eigen::Vector4f q = T * Eigen::Vector4f(s.x[j], s.y[j], s.z[j], 1.0F);
      const Eigen::Vector3d qd = q.head<3>().cast<double>();
      if (!qd.allFinite() || !near.contains(qd)) continue;
      taken[j] = true;
      cropped.emplace_back(qd.x(), qd.y(), qd.z(), 1.0);
    }
    voxels_.add(cropped);
  }
  return true;
}

}  // namespace rigcal::calib
