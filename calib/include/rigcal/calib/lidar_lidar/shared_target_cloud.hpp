#pragma once
// The later frames' augmented targets as one cloud in the map frame. Frames of a drive see the same surfaces
// from places metres apart: on the street preset the 17 targets of its three lidars held 6.2x the voxels of
// their union, a lidar's 5-6 targets 2.1-2.8x. So once the first frame has placed the lidar, each later frame
// adds its window's mapping clouds cropped near its source (under T_map_mapping_at_scan · {guess, best}) to one
// map-frame cloud, voxelised at leaf_size_dense_map, and one Target serves them all through each frame's
// anchor (registration::SourceTarget::anchor = T_map_mapping_at_scan).
#include <cstddef>
#include <map>
#include <vector>

#include "rigcal/config/parameters.hpp"
#include "rigcal/core/pose.hpp"
#include "rigcal/pipeline/calibration_dataset.hpp"
#include "rigcal/pipeline/target_window_picks.hpp"
#include "rigcal/registration/deadline.hpp"
#include "rigcal/registration/point_cloud.hpp"
#include "rigcal/registration/voxel_accumulator.hpp"

namespace rigcal::calib {

class SharedTargetCloud {
 public:
  /// `max_clouds`: of each frame's window, as AugmentedTargetOptions::max_clouds.
  SharedTargetCloud(const pipeline::CalibrationDataset& dataset, const config::Parameters& params,
                    std::size_t max_clouds = pipeline::kTargetWindowClouds);

  /// Adds dataset.frames[frame]'s crop: the points of its window's clouds (targetWindow) within `radius` of
  /// `source` placed by one of `poses` (mapping frame at the scan), each mapping point at most once over all
  /// frames. False, with the frame not (or partly) added, when the deadline expired between clouds.
  bool add(std::size_t frame, const registration::PointCloud& source, const std::vector<Pose>& poses, double radius,
           const registration::Deadline& deadline);

  /// The frame's anchor: where its mapping pose lies in this cloud's (the map's) frame.
  [[nodiscard]] Pose anchor(std::size_t frame) const;

  [[nodiscard]] std::size_t voxels() const { return voxels_.voxels(); }
  [[nodiscard]] std::size_t pointsAdded() const { return voxels_.added(); }
  /// The voxel centroids, in the map frame.
  [[nodiscard]] registration::PointCloud cloud() const { return voxels_.centroids(); }

 private:
  const pipeline::CalibrationDataset& dataset_;
  const config::Parameters& params_;
  std::size_t max_clouds_;
  registration::VoxelAccumulator voxels_;
  std::map<std::size_t, std::vector<bool>> taken_;  // per mapping cloud: which of its points are in already
};

}  // namespace rigcal::calib
