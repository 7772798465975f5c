#pragma once
// The target side of a lidar-lidar registration: the mapping lidar's "augmented" cloud around a selected
// keyframe. The mapping clouds of its window, keyframes kid−N to kid+N (N = dense_pointcloud_num_keyframes;
// which of them: pipeline/target_window_picks.hpp), are expressed in the mapping-lidar frame interpolated
// at the calibration scan's stamp, voxelised at leaf_size_dense_map and cropped to the source's bounding box
// (under the initial extrinsic) widened by |t_initial|, then built once into a registration Target (tree,
// covariances, NDT grid).
#include <cstddef>
#include <memory>
#include <optional>
#include <vector>

#include "rigcal/config/parameters.hpp"
#include "rigcal/core/pose.hpp"
#include "rigcal/pipeline/calibration_dataset.hpp"
#include "rigcal/registration/deadline.hpp"
#include "rigcal/registration/point_cloud.hpp"
#include "rigcal/registration/target.hpp"

namespace rigcal::calib {

struct AugmentedTargetOptions {
  /// At most this many mapping clouds per target, evenly spread over the window (always keeping the
  /// keyframe's own): a stored frame every few centimetres of path gives ~150 clouds per window, most
  /// of them redundant after voxelising; 0 = all. The pipeline hands over only the (at most
  /// pipeline::kTargetWindowClouds) keyframes' clouds a frame's target takes (CalibrationFrame::window):
  /// more than that picks nothing more, fewer spreads over those.
  std::size_t max_clouds = pipeline::kTargetWindowClouds;
  double ndt_resolution = 1.0;  // the ensemble's NDT grid
  int num_threads = 1;
  /// The crop stops between mapping clouds once this expires and returns an empty cloud: on a busy machine
  /// cropping a dozen clouds takes longer than a short calibration deadline.
  registration::Deadline deadline;
  /// Once the extrinsic is known to within the registrators' reach: keep only the mapping points within
  /// near_radius of the source placed by one of these poses (SourceNeighbourhood) instead of the box under
  /// the initial guess. Empty: the box.
  std::vector<Pose> near_poses;
  double near_radius = 0.6;  // nearTargetRadius(params) for the defaults
};

/// How far from the source a later frame's target must reach: the coarse registrations' correspondence
/// distance (which covers the score's) plus what the first frame's estimate may still be off at the
/// farthest source point (a few cm; 0.1 m allowed).
double nearTargetRadius(const config::Parameters& params);

struct AugmentedTarget {
  std::shared_ptr<const registration::Target> target;  // in the mapping frame at the scan stamp
  std::size_t clouds_used = 0;
  std::size_t points_before_voxel = 0;  // after the crop
};

/// Which dataset.mapping_clouds form the window of dataset.frames[frame] (indices, by sequence): the
/// frame's own `window` when the pipeline gave one, else every cloud between keyframes kid±N; then at most
/// max_clouds of them (spreadWindowPicks()).
/// Throws std::invalid_argument when the frame's keyframe is not a keyframe of dataset.trajectory.
std::vector<std::size_t> targetWindow(const pipeline::CalibrationDataset& dataset, std::size_t frame,
                                      const config::Parameters& params, std::size_t max_clouds);

/// The mapping clouds of a frame's target window (targetWindow()), held: the dataset may let go of its own
/// references (calibrateLidarLidarDroppingClouds) while a crop of these runs on another thread.
struct TargetWindowClouds {
  std::vector<pipeline::MappingCloud> clouds;
  Pose T_scan_map = Pose::Identity();  // the map into the mapping-lidar frame at the calibration scan's stamp
  Pose T_mapping_calib_guess = Pose::Identity();
};

TargetWindowClouds targetWindowClouds(const pipeline::CalibrationDataset& dataset, std::size_t frame,
                                      const config::Parameters& params, std::size_t max_clouds);

/// The augmented cloud of a window (before building the Target), cropped around `source` placed by the
/// initial extrinsic (or near it under options.near_poses). Empty when options.deadline expired during the
/// crop. Reads nothing but its arguments: safe on a thread of its own.
registration::PointCloud augmentedCloud(const TargetWindowClouds& window, const registration::PointCloud& source,
                                        const config::Parameters& params, const AugmentedTargetOptions& options,
                                        std::size_t* points_before_voxel = nullptr);

/// The same for dataset.frames[frame] (its window picked with options.max_clouds).
registration::PointCloud augmentedCloud(const pipeline::CalibrationDataset& dataset, std::size_t frame,
                                        const registration::PointCloud& source, const config::Parameters& params,
                                        const AugmentedTargetOptions& options, std::size_t* clouds_used = nullptr,
                                        std::size_t* points_before_voxel = nullptr);

AugmentedTarget buildAugmentedTarget(const pipeline::CalibrationDataset& dataset, std::size_t frame,
                                     const registration::PointCloud& source, const config::Parameters& params,
                                     const AugmentedTargetOptions& options = {});

}  // namespace rigcal::calib
