#pragma once
// Every file a calibration run writes into its output folder, in one order for `calibrate` and
// `calibrate --static`: calibration.yaml, then (when there are datasets) the before/after clouds, map.pcd
// and overview.png, then report.json last, with the time the others took as its "outputs" stage.
#include <filesystem>

#include "rigcal/calib/outputs/calibration_outcome.hpp"

namespace rigcal::calib {

/// Each file written atomically. Throws std::runtime_error "<path>: <why>" for the first that cannot be.
void writeCalibrationOutputs(const std::filesystem::path& out, CalibrationOutcome& outcome);

}  // namespace rigcal::calib
