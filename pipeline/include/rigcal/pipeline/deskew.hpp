#pragma once
// Motion compensation: re-expresses every point of a sweep in the sensor frame at one reference time,
// using the sensor's motion during the sweep.
#include <algorithm>
#include <cstddef>
#include <functional>

#include "rigcal/core/pose.hpp"
#include "rigcal/core/scan.hpp"

namespace rigcal::pipeline {

/// T_ref_sensor(t): the sensor's pose at time t, expressed in the sensor frame at the reference time.
using SensorMotion = std::function<Pose(TimeNs t)>;

/// Constant velocity: the sensor moved by `T_prev_curr` between two stamps `dt_ns` apart and keeps
/// that twist; the reference is at `t_ref`.
SensorMotion constantVelocity(const Pose& T_prev_curr, TimeNs dt_ns, TimeNs t_ref);

/// Moves each point p (taken at its own time t) to T_ref_sensor(t)·p. Poses are evaluated once per
/// `bin_ns` of point time (100 µs: < 0.2 mm at 5 km/h) and shared by the points in that bin.
void deskew(Scan& scan, const SensorMotion& T_ref_sensor, TimeNs bin_ns = 100 * kNsPerUs);

/// T_map_mapping(t): the mapping lidar's pose in the map at time t.
using TrajectoryLookup = std::function<Pose(TimeNs t)>;

/// The one rule for a pose on the mapping trajectory (`n` poses, stamps strictly increasing, read through
/// stamp(i) and pose(i)): lerp/slerp between the two poses around t; outside the trajectory the nearest two
/// extrapolate (a sweep's edge a few milliseconds past the last pose keeps moving); one pose: that pose;
/// none: identity.
template <class StampAt, class PoseAt>
Pose poseOnTrajectory(std::size_t n, StampAt&& stamp, PoseAt&& pose, TimeNs t) {
  if (n == 0) return Pose::Identity();
  if (n == 1) return pose(0);
  std::size_t lo = 0, hi = n;  // first index with stamp > t
  while (lo < hi) {
    const std::size_t mid = lo + (hi - lo) / 2;
    if (t < stamp(mid)) hi = mid;
    else lo = mid + 1;
  }
  const std::size_t after = std::clamp<std::size_t>(lo, 1, n - 1);
  return interpolateAt(stamp(after - 1), pose(after - 1), stamp(after), pose(after), t);
}

/// A calibration lidar's sweep deskewed through the mapping trajectory: the calibration lidar moves as
/// T_map_mapping(t)·T_mapping_calib; each point ends in the calibration-lidar frame at scan.stamp_ns.
void deskewThroughMapping(Scan& scan, const TrajectoryLookup& T_map_mapping, const Pose& T_mapping_calib);

}  // namespace rigcal::pipeline
