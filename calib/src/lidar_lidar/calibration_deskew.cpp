#include "rigcal/calib/lidar_lidar/calibration_deskew.hpp"

#include <algorithm>
#include <stdexcept>

#include "rigcal/pipeline/deskew.hpp"

namespace rigcal::calib {

Pose mappingPoseAt(const std::vector<pipeline::MappingFrame>& trajectory, TimeNs t) {
  if (trajectory.size() < 2) throw std::invalid_argument("mapping trajectory: fewer than two poses to interpolate");
  for (std::size_t i = 1; i < trajectory.size(); ++i)
    if (trajectory[i - 1].stamp_ns >= trajectory[i].stamp_ns)
      throw std::invalid_argument("mapping trajectory: stamps are not strictly increasing");
  return pipeline::poseOnTrajectory(
      trajectory.size(), [&](std::size_t i) { return trajectory[i].stamp_ns; },
      [&](std::size_t i) { return trajectory[i].T_map_lidar; }, t);
}

Scan deskewThroughMapping(const Scan& raw, const std::vector<pipeline::MappingFrame>& trajectory,
                          const Pose& T_mapping_calib) {
  Scan out = raw;
  if (out.empty()) return out;
  mappingPoseAt(trajectory, raw.stamp_ns);  // throws for a trajectory it cannot interpolate, once
  const auto stamp = [&](std::size_t i) { return trajectory[i].stamp_ns; };
  const auto pose = [&](std::size_t i) { return trajectory[i].T_map_lidar; };
  pipeline::deskewThroughMapping(
      out, [&](TimeNs t) { return pipeline::poseOnTrajectory(trajectory.size(), stamp, pose, t); }, T_mapping_calib);
  return out;
}

}  // namespace rigcal::calib
