#pragma once
// `rigcal calibrate --static`: the vehicle stands still (calibrate_command.cpp hands over here).
#include <string>

#include "pipeline_options.hpp"

namespace rigcal::app {

/// Captures static_capture_s of every lidar, refuses when the vehicle moved (when and how much), registers
/// each calibration lidar's accumulated cloud to the mapping lidar's, fits base-lidar from the ground, and
/// writes the outputs of a driving calibration. Throws CommandFailed with the exit code.
void runCalibrateStatic(const std::string& config, const PipelineCliOptions& input, const std::string& out,
                        double deadline);

}  // namespace rigcal::app
