#include "rigcal/pipeline/deskew.hpp"

#include <algorithm>
#include <vector>

namespace rigcal::pipeline {

SensorMotion constantVelocity(const Pose& T_prev_curr, TimeNs dt_ns, TimeNs t_ref) {
  const Vector6d twist_per_ns = logSE3(T_prev_curr) / double(dt_ns);
  return [twist_per_ns, t_ref](TimeNs t) { return expSE3(twist_per_ns * double(t - t_ref)); };
}

void deskew(Scan& scan, const SensorMotion& T_ref_sensor, TimeNs bin_ns) {
  if (scan.empty()) return;
  const std::uint32_t max_offset = *std::max_element(scan.offset_ns.begin(), scan.offset_ns.end());
  const std::size_t bins = std::size_t(max_offset / bin_ns) + 1;
  std::vector<Eigen::Matrix<float, 3, 4>> poses(bins);
  for (std::size_t b = 0; b < bins; ++b)  // each bin uses the pose at its centre
    poses[b] = T_ref_sensor(scan.stamp_ns + TimeNs(b) * bin_ns + bin_ns / 2).matrix().topRows<3>().cast<float>();
  for (std::size_t i = 0; i < scan.size(); ++i) {
    const auto& T = poses[scan.offset_ns[i] / bin_ns];
    const Eigen::Vector3f p = T.leftCols<3>() * Eigen::Vector3f(scan.x[i], scan.y[i], scan.z[i]) + T.col(3);
    scan.x[i] = p.x();
    scan.y[i] = p.y();
    scan.z[i] = p.z();
  }
}

void deskewThroughMapping(Scan& scan, const TrajectoryLookup& T_map_mapping, const Pose& T_mapping_calib) {
  if (scan.empty()) return;
  const Pose T_ref_map = (T_map_mapping(scan.stamp_ns) * T_mapping_calib).inverse();
  deskew(scan, [&](TimeNs t) { return Pose(T_ref_map * T_map_mapping(t) * T_mapping_calib); });
}

}  // namespace rigcal::pipeline
