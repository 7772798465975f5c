#pragma once
// The clouds a user opens next to the result: map.pcd (the mapper's map, or else the mapping lidar's
// clouds around the selected keyframes, in the map frame) and, per calibration lidar, <name>_before.pcd / <name>_after.pcd (its
// selected frames placed in the same map frame through the initial and the calibrated extrinsic).
#include <filesystem>
#include <vector>

#include <Eigen/Core>

#include "rigcal/calib/outputs/calibration_outcome.hpp"
#include "rigcal/core/pose.hpp"
#include "rigcal/pipeline/calibration_dataset.hpp"

namespace rigcal::calib {

/// The mapping clouds of all datasets (each stored frame once), in the map frame, voxelised at `leaf`.
std::vector<Eigen::Vector3d> mapCloud(const std::vector<pipeline::CalibrationDataset>& datasets, double leaf);

/// The outcome's map: its map_cloud as it is when set (no copy through a voxel grid), else
/// mapCloud(datasets, leaf).
std::vector<Eigen::Vector3d> outcomeMapCloud(const CalibrationOutcome& outcome, double leaf);

/// A calibration lidar's selected frames (deskewed), in the map frame through T_mapping_calib.
std::vector<Eigen::Vector3d> calibrationCloudInMap(const pipeline::CalibrationDataset& dataset,
                                                   const Pose& T_mapping_calib);

/// Binary PCD with x y z (float). Throws std::runtime_error naming the path on failure.
void writeCloudPcd(const std::filesystem::path& path, const std::vector<Eigen::Vector3d>& points);

/// map.pcd and every <name>_before.pcd / <name>_after.pcd in `dir`.
void writeCalibrationClouds(const std::filesystem::path& dir, const CalibrationOutcome& outcome, double map_leaf = 0.1);

}  // namespace rigcal::calib
