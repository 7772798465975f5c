#include "rigcal/calib/calibration_deskew.hpp"

#include <algorithm>
#include <stdexcept>

#include "rigcal/pipeline/deskew.hpp"

namespace rigcal::calib {

Pose mappingPoseAt(const std::vector<pipeline::MappingFrame>& trajectory, TimeNs t) {
  if (trajectory.size() < 2) throw std::invalid_argument("mapping trajectory: fewer than two poses to interpolate");
  auto after = std::upper_bound(trajectory.begin(), trajectory.end(), t,
                                [](TimeNs value, const pipeline::MappingFrame& f) { return value < f.stamp_ns; });
  // Clamp to an existing bracket; outside the trajectory the nearest pair extrapolates.
  if (after == trajectory.begin()) ++after;
  if (after == trajectory.end()) --after;
  const auto before = after - 1;
  if (before->stamp_ns >= after->stamp_ns)
    throw std::invalid_argument("mapping trajectory: stamps are not strictly increasing");
  return interpolateAt(before->stamp_ns, before->T_map_lidar, after->stamp_ns, after->T_map_lidar, t);
}

Scan deskewThroughMapping(const Scan& raw, const std::vector<pipeline::MappingFrame>& trajectory,
                          const Pose& T_mapping_calib) {
  Scan out = raw;
  if (out.empty()) return out;
  const Pose T_map_calib_ref = mappingPoseAt(trajectory, raw.stamp_ns) * T_mapping_calib;
  const Pose T_ref_map = T_map_calib_ref.inverse();
  pipeline::deskew(out, [&](TimeNs t) { return Pose(T_ref_map * mappingPoseAt(trajectory, t) * T_mapping_calib); });
  return out;
}

}  // namespace rigcal::calib
