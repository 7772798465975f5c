#pragma once
// report.json: what was selected and why every other candidate was rejected, every registration the
// ensemble ran (score, time, status), per-registrator totals, the deadline, stage timings, the input
// summary and the version, per calibration lidar; and the base-lidar result.
#include <filesystem>

#include <nlohmann/json.hpp>

#include "rigcal/calib/outputs/calibration_outcome.hpp"

namespace rigcal::calib {

nlohmann::json reportJson(const CalibrationOutcome& outcome);
/// Throws std::runtime_error "<path>: <why>" when it cannot be written.
void writeReportJson(const std::filesystem::path& path, const CalibrationOutcome& outcome);

}  // namespace rigcal::calib
