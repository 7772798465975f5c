#include "rigcal/pipeline/calibration_crop.hpp"

namespace rigcal::pipeline {

void cropCalibrationCloud(Scan& scan, const Pose& T_mapping_calib, const config::Parameters& params) {
  const double min2 = params.min_calibration_range * params.min_calibration_range;
  const double max2 = params.max_calibration_range * params.max_calibration_range;
  const Eigen::Matrix3d R = T_mapping_calib.linear();
  const Eigen::Vector3d t = T_mapping_calib.translation();
  scan.filter([&](std::size_t i) {
    const Eigen::Vector3d p(scan.x[i], scan.y[i], scan.z[i]);
    const double r2 = p.squaredNorm();
    if (!(r2 >= min2 && r2 < max2)) return false;  // also drops NaN
    return !params.crop_z_calibration_pointclouds ||
           (R.row(2).dot(p) + t.z()) <= params.crop_z_calibration_pointclouds_value;
  });
}

}  // namespace rigcal::pipeline
