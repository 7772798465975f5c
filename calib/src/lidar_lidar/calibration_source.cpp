#include "rigcal/calib/lidar_lidar/calibration_source.hpp"

#include "rigcal/registration/covariance.hpp"

namespace rigcal::calib {

registration::PointCloud buildSource(const Scan& deskewed, const config::Parameters& params,
                                     const SourceOptions& options) {
  registration::PointCloud cloud;
  cloud.points.reserve(deskewed.size());
  const double min_sq = params.min_calibration_range * params.min_calibration_range;
  const double max_sq = params.max_calibration_range * params.max_calibration_range;
  for (std::size_t i = 0; i < deskewed.size(); ++i) {
    const double x = deskewed.x[i], y = deskewed.y[i], z = deskewed.z[i];
    const double r2 = x * x + y * y + z * z;
    if (!(r2 >= min_sq && r2 < max_sq)) continue;  // also drops NaN
    cloud.add(x, y, z);
  }
  if (options.covariances && cloud.size() >= 3) {
    registration::CovarianceOptions cov;
    cov.num_threads = options.num_threads;
    registration::estimateCovariances(cloud, cov);
  }
  return cloud;
}

}  // namespace rigcal::calib
