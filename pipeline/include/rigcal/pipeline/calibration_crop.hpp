#pragma once
// The crop every calibration lidar's deskewed cloud gets before frame selection and calibration: the
// calibration range limits (in its own frame) and, with crop_z_calibration_pointclouds, a height limit in
// the mapping lidar's frame through the initial extrinsic. The height limit matters most for unusual
// mounts: a lidar rolled 90° sweeps container walls up to 10 m high beside the vehicle, where an upright
// mapping lidar never looks.
#include "rigcal/config/parameters.hpp"
#include "rigcal/core/pose.hpp"
#include "rigcal/core/scan.hpp"

namespace rigcal::pipeline {

/// Keeps the points of `scan` (calibration-lidar frame) with range in [min_calibration_range,
/// max_calibration_range) and, when params.crop_z_calibration_pointclouds, height in the mapping frame
/// (through T_mapping_calib) at most crop_z_calibration_pointclouds_value.
void cropCalibrationCloud(Scan& scan, const Pose& T_mapping_calib, const config::Parameters& params);

}  // namespace rigcal::pipeline
