#include "rigcal/calib/lidar_lidar/augmented_target.hpp"

#include <algorithm>
#include <limits>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "rigcal/calib/lidar_lidar/source_neighbourhood.hpp"
#include "rigcal/pipeline/target_window_picks.hpp"
#include "rigcal/registration/voxel_accumulator.hpp"

namespace rigcal::calib {

std::vector<std::size_t> targetWindow(const pipeline::CalibrationDataset& dataset, std::size_t frame,
                                      const config::Parameters& params, std::size_t max_clouds) {
  const auto& pairing = dataset.frames.at(frame).pairing;
  if (pairing.keyframe_frame >= dataset.trajectory.size() ||
      dataset.trajectory[pairing.keyframe_frame].keyframe_index < 0) {
    std::ostringstream msg;
    msg << "calibration frame " << frame << ": keyframe_frame " << pairing.keyframe_frame
        << " is not a keyframe of the mapping trajectory (" << dataset.trajectory.size() << " frames)";
    throw std::invalid_argument(msg.str());
  }
  const auto& keyframe = dataset.trajectory[pairing.keyframe_frame];
  std::vector<std::size_t> window;
  std::size_t own = std::numeric_limits<std::size_t>::max();
  const auto consider = [&](std::size_t i) {
    const auto& c = dataset.mapping_clouds.at(i);
    if (c.cloud == nullptr) return;
    if (c.frame.sequence == keyframe.sequence) own = window.size();
    window.push_back(i);
  };
  const auto& picked_by_pipeline = dataset.frames[frame].window;
  if (!picked_by_pipeline.empty()) {
    // The pipeline kept only the clouds this frame's target is built from (the same spread as below).
    for (const std::size_t i : picked_by_pipeline) consider(i);
  } else {
    const int lo = keyframe.keyframe_index - params.dense_pointcloud_num_keyframes;
    const int hi = keyframe.keyframe_index + params.dense_pointcloud_num_keyframes;
    // The window's sequence range: from keyframe lo (or the start) to keyframe hi (or the end). Only
    // keyframes count: every other frame's keyframe_index is -1, which a window starting one keyframe
    // before the first (lo = -1) had matched, leaving it empty.
    std::uint64_t seq_lo = 0, seq_hi = std::numeric_limits<std::uint64_t>::max();
    for (const auto& f : dataset.trajectory) {
      if (f.keyframe_index < 0) continue;
      if (f.keyframe_index == lo) seq_lo = f.sequence;
      if (f.keyframe_index == hi) seq_hi = f.sequence;
    }
    for (std::size_t i = 0; i < dataset.mapping_clouds.size(); ++i) {
      const auto& c = dataset.mapping_clouds[i];
      if (c.frame.sequence >= seq_lo && c.frame.sequence <= seq_hi) consider(i);
    }
  }
  // Evenly spread picks, the keyframe's own cloud always among them.
  std::vector<std::size_t> picked;
  for (const std::size_t k : pipeline::spreadWindowPicks(window.size(), own, max_clouds)) picked.push_back(window[k]);
  return picked;
}

double nearTargetRadius(const config::Parameters& params) {
  constexpr double kEstimateError = 0.1;
  return std::max(params.max_corr_dist_coarse, params.calibration_eval_max_corr_distance) + kEstimateError;
}

TargetWindowClouds targetWindowClouds(const pipeline::CalibrationDataset& dataset, std::size_t frame,
                                      const config::Parameters& params, std::size_t max_clouds) {
  TargetWindowClouds window;
  for (const std::size_t i : targetWindow(dataset, frame, params, max_clouds))
    window.clouds.push_back(dataset.mapping_clouds[i]);
  window.T_scan_map = dataset.frames[frame].pairing.T_map_mapping_at_scan.inverse();
  window.T_mapping_calib_guess = dataset.T_mapping_calib_guess;
  return window;
}

registration::PointCloud augmentedCloud(const TargetWindowClouds& window, const registration::PointCloud& source,
                                        const config::Parameters& params, const AugmentedTargetOptions& options,
                                        std::size_t* points_before_voxel) {
  // Crop box: the source under the initial extrinsic, widened by |t_initial| (the guess may be that far off).
  const Pose& guess = window.T_mapping_calib_guess;
  Eigen::Vector3d box_min = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d box_max = -box_min;
  for (const auto& p : source.points) {
    const Eigen::Vector3d q = guess * p.head<3>();
    box_min = box_min.cwiseMin(q);
    box_max = box_max.cwiseMax(q);
  }
  const double margin = guess.translation().norm();
  box_min.array() -= margin;
  box_max.array() += margin;
  std::optional<SourceNeighbourhood> near;
  if (!options.near_poses.empty()) near.emplace(source, options.near_poses, options.near_radius);
  const auto keep = [&](const Eigen::Vector3d& q) {
    if (near) return near->contains(q);
    return (q.array() >= box_min.array()).all() && (q.array() <= box_max.array()).all();
  };

  // Each cloud is cropped and voxelised before the next (the same centroids as voxelising the whole crop
  // at once), so the deadline is looked at between clouds for all of the work.
  std::optional<registration::VoxelAccumulator> voxels;
  std::vector<Eigen::Vector4d> cropped;
  for (const auto& mc : window.clouds) {
    if (options.deadline.expired()) return {};
    if (mc.cloud == nullptr) continue;
    const Eigen::Matrix4f T = (window.T_scan_map * mc.frame.T_map_lidar).matrix().cast<float>();
    const Scan& s = *mc.cloud;
    cropped.clear();
    for (std::size_t j = 0; j < s.size(); ++j) {
      const Eigen::Vector4f q = T * Eigen::Vector4f(s.x[j], s.y[j], s.z[j], 1.0F);
      const Eigen::Vector3d qd = q.head<3>().cast<double>();
      if (!qd.allFinite() || !keep(qd)) continue;
      cropped.emplace_back(qd.x(), qd.y(), qd.z(), 1.0);
    }
    if (cropped.empty()) continue;
    if (!voxels) voxels.emplace(params.leaf_size_dense_map, cropped.size() * window.clouds.size());
    voxels->add(cropped);
  }
  if (points_before_voxel != nullptr) *points_before_voxel = voxels ? voxels->added() : 0;
  if (!voxels) return {};
  return voxels->centroids();
}

registration::PointCloud augmentedCloud(const pipeline::CalibrationDataset& dataset, std::size_t frame,
                                        const registration::PointCloud& source, const config::Parameters& params,
                                        const AugmentedTargetOptions& options, std::size_t* clouds_used,
                                        std::size_t* points_before_voxel) {
  const auto window = targetWindowClouds(dataset, frame, params, options.max_clouds);
  if (clouds_used != nullptr) *clouds_used = window.clouds.size();
  return augmentedCloud(window, source, params, options, points_before_voxel);
}

AugmentedTarget buildAugmentedTarget(const pipeline::CalibrationDataset& dataset, std::size_t frame,
                                     const registration::PointCloud& source, const config::Parameters& params,
                                     const AugmentedTargetOptions& options) {
  AugmentedTarget out;
  auto cloud = augmentedCloud(dataset, frame, source, params, options, &out.clouds_used, &out.points_before_voxel);
  registration::TargetOptions to;
  to.normals_and_covariances = true;
  to.ndt_resolutions = {options.ndt_resolution};
  to.num_threads = options.num_threads;
  out.target = std::make_shared<const registration::Target>(std::move(cloud), to);
  return out;
}

}  // namespace rigcal::calib
