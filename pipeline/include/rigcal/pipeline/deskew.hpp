#pragma once
// Motion compensation: re-expresses every point of a sweep in the sensor frame at one reference time,
// using the sensor's motion during the sweep.
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

}  // namespace rigcal::pipeline
