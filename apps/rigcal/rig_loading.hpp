#pragma once
// How every command reads its files, so the same mistake gets the same exit code everywhere:
// a file named on the command line that is missing, a folder or unreadable is an input error (4);
// a rig file that says something wrong (including a calibration/metadata file it names that is
// missing, unreadable or unparsable, or a model no decoder knows) is a config error (3) with its position.
#include <string>

#include "rigcal/config/rig_config.hpp"

namespace rigcal::app {

/// Throws CommandFailed(kExitInput, "<path>: <what> not found | is not a regular file | is not readable").
void requireInputFile(const std::string& path, const std::string& what);

/// requireInputFile(path, "rig file"), config::loadRigConfig, then each sensor's decoder built once
/// (model known, calibration/metadata parsed). What `check-config` accepts, `calibrate` accepts.
config::RigConfig loadRig(const std::string& path);

}  // namespace rigcal::app
