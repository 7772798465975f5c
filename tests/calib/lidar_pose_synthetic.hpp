#pragma once
// A synthetic lidar + pose-sensor recording for the lidar-pose calibration tests and benchmark: a
// procedural scene (ground, the walls of a 60 m square yard, oriented boxes), a pose trajectory (a
// figure of eight with yaw following the heading, optional roll/pitch/heave), and a spinning 16-ring
// lidar mounted at a known T_pose_lidar whose clock lags the pose clock by a known offset.
#include <cstdint>
#include <vector>

#include "rigcal/calib/lidar_pose/lidar_pose_points.hpp"
#include "rigcal/core/pose.hpp"
#include "rigcal/core/scan.hpp"

namespace rigcal::test {

struct SyntheticOptions {
  bool planar = false;         // no roll, pitch or heave (a vehicle on flat ground)
  double roll_amplitude_deg = 15.0, pitch_amplitude_deg = 12.0;  // unless planar (a well-shaken rig)
  double duration_s = 10.0;    // lidar recording length (pose coverage adds a margin)
  double pose_rate_hz = 100.0;
  double pose_margin_s = 0.5;  // poses start this long before the first lidar point (and end after)
  int rings = 16;
  int columns = 1000;          // firings per 100 ms sweep
  double range_noise_m = 0.003;
  Pose T_pose_lidar = fromXyzRpy({0.5, -0.2, 0.3, deg2rad(3.0), deg2rad(-4.0), deg2rad(10.0)});
  double time_offset_s = 0.015;  // pose time = lidar time + offset
  TimeNs start_ns = 1'700'000'000'000'000'000;
  std::uint64_t seed = 7;
  /// Rays whose return the calibration's selection would drop are not cast (their point is a
  /// placeholder at the origin): the calibration never looks at them, and the tests stay fast.
  calib::LidarPointSelection selection;
};

struct SyntheticRecording {
  std::vector<Scan> scans;
  std::vector<TimeNs> pose_stamps;
  std::vector<Pose> poses;  // T_world_pose
};

/// T_world_pose at time t (seconds since start_ns, pose clock).
Pose syntheticPose(const SyntheticOptions& options, double t);

SyntheticRecording makeSyntheticRecording(const SyntheticOptions& options);

}  // namespace rigcal::test
