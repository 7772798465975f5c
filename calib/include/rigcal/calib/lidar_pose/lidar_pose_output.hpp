#pragma once
// What `rigcal calibrate-pose` writes: lidar_align's calibration text (same sections, so its users
// and their scripts find what they expect) followed by our observability report, a calibration.yaml in
// the rig's parent/child x y z roll pitch yaw layout plus the time offset (calibration_yaml_writer.hpp, the
// one YAML writer), and the fused cloud as a
// binary PLY with real intensity and a separate time field (lidar_align stored point times in the
// intensity field).
#include <filesystem>
#include <string>

#include <Eigen/Core>

#include "rigcal/calib/lidar_pose/lidar_pose_calibration.hpp"

namespace rigcal::calib {

/// Sections, as lidar_align: transformation vector (x, y, z, rotation vector), 4×4 matrix, translation,
/// Hamilton quaternion (w, x, y, z), time offset to add to lidar timestamps, static TF publisher line;
/// then the costs, evaluations, stage times, point counts and observability. `origin` is what the pose
/// reader subtracted (PoseCsv::origin), reported so the fused cloud can be placed back.
std::string lidarPoseCalibrationText(const LidarPoseResult& result,
                                     const Eigen::Vector3d& origin = Eigen::Vector3d::Zero());
void writeLidarPoseCalibrationText(const std::filesystem::path& path, const LidarPoseResult& result,
                                   const Eigen::Vector3d& origin = Eigen::Vector3d::Zero());

/// The returns used, fused with the result: x y z (float, world frame as read, i.e. re-centred),
/// intensity (float, as decoded) and time (double, seconds: lidar time + time offset, the pose
/// sensor's clock). Points without a pose are skipped (there are none after calibrateLidarPose).
void writeLidarPoseCloud(const std::filesystem::path& path, const LidarPoints& points,
                         const PoseTrajectory& trajectory, const Pose& T_pose_lidar, double time_offset_s);

}  // namespace rigcal::calib
