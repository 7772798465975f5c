#pragma once
// calibration.yaml: per parent/child frame pair x, y, z, roll, pitch, yaw (Autoware sensor-kit style,
// 6 decimals, metres and radians, R = Rz(yaw)·Ry(pitch)·Rx(roll)), plus T_base_sensor for every sensor.
#include <filesystem>
#include <string>

#include "rigcal/calib/calibration_outcome.hpp"

namespace rigcal::calib {

std::string calibrationYaml(const CalibrationOutcome& outcome);
/// Throws std::runtime_error "<path>: <why>" when it cannot be written.
void writeCalibrationYaml(const std::filesystem::path& path, const CalibrationOutcome& outcome);

}  // namespace rigcal::calib
