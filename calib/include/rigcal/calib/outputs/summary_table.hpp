#pragma once
// The summary printed on stdout at the end of `rigcal calibrate`: per sensor the result (x y z roll pitch
// yaw of T_parent_child), the change from the initial guess, the score and the frames used.
#include <string>

#include "rigcal/calib/outputs/calibration_outcome.hpp"

namespace rigcal::calib {

std::string summaryTable(const CalibrationOutcome& outcome);

}  // namespace rigcal::calib
