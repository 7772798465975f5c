#pragma once
// calibration.yaml, the one writer of it for every command: per parent/child frame pair x, y, z, roll,
// pitch, yaw (Autoware sensor-kit style, 6 decimals, metres and radians, R = Rz(yaw)·Ry(pitch)·Rx(roll)).
// `calibrate` adds T_base_sensor for every sensor; `calibrate-pose` adds the time offset.
#include <filesystem>
#include <string>

#include "rigcal/calib/outputs/calibration_outcome.hpp"
#include "rigcal/calib/lidar_pose/lidar_pose_calibration.hpp"

namespace rigcal::calib {

std::string calibrationYaml(const CalibrationOutcome& outcome);
/// Throws std::runtime_error "<path>: <why>" when it cannot be written.
void writeCalibrationYaml(const std::filesystem::path& path, const CalibrationOutcome& outcome);

/// calibrate-pose's: parent_frame: { child_frame: { x, y, z, roll, pitch, yaw, time_offset_s } } (time with 9
/// decimals), the parameters the motion left poorly constrained in a comment.
std::string lidarPoseYaml(const LidarPoseResult& result, const std::string& parent_frame = "pose_sensor",
                          const std::string& child_frame = "lidar");
void writeLidarPoseYaml(const std::filesystem::path& path, const LidarPoseResult& result,
                        const std::string& parent_frame = "pose_sensor", const std::string& child_frame = "lidar");

}  // namespace rigcal::calib
