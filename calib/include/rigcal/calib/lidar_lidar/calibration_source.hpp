#pragma once
// The source side of a lidar-lidar registration: the deskewed calibration cloud within the calibration
// range limits, with the covariances GICP needs estimated once (every registrator and start reuses them).
#include "rigcal/config/parameters.hpp"
#include "rigcal/core/scan.hpp"
#include "rigcal/registration/point_cloud.hpp"

namespace rigcal::calib {

struct SourceOptions {
  bool covariances = true;  // for GICP; the batched ICP of the final step does not need them
  int num_threads = 1;
};

/// Finite points with range in [min_calibration_range, max_calibration_range).
registration::PointCloud buildSource(const Scan& deskewed, const config::Parameters& params,
                                     const SourceOptions& options = {});

}  // namespace rigcal::calib
