#pragma once
// Which calibration parameters the recorded motion can determine. lidar_align returns a value for every
// parameter whether or not the motion constrains it ("accurate results require a lot of non-planar
// motion"); we measure the excitation from the pose trajectory and flag — and, by default, hold at the
// initial guess — what it leaves poorly constrained.
//
// Excitation, over the poses spanning the lidar points:
//  - rotation range about each pose-frame axis a: peak-to-peak of ∫ω_a dt, ω the body angular rate
//    (from log(R_i⁻¹·R_i+1) between consecutive poses), in degrees;
//  - RMS body angular rate per axis, path length, smallest and largest speed.
// Rules (r_a = rotation range about a, R = min_rotation_range_deg):
//  - translation along a: needs rotation about another axis (r_b ≥ R for some b ≠ a). Rotating about a
//    alone moves a lever arm along a nowhere: an error in it shifts the fused cloud uniformly.
//    Planar (yaw-only) motion leaves z unconstrained, and z also needs a roll or pitch range of
//    min_tilt_range_for_z_deg (see ObservabilitySettings).
//  - roll and pitch (rotation about pose x and y): need non-planar motion, max(r_x, r_y) ≥ R. Under
//    yaw-only motion a tilt error only shows as a heading-dependent tilt of the scene, which trades off
//    against z and the time offset (lidar_align's own advice; see reference/lidar_align.md).
//  - yaw: needs some rotation (any r_a ≥ R) or travel (path ≥ min_path_length_m).
//  - time offset: needs some rotation (any r_a ≥ R) or a change of speed (max − min speed ≥
//    min_speed_range_mps). Under constant straight motion an offset only shifts the cloud.
#include <array>
#include <string>

#include "rigcal/calib/lidar_pose/pose_trajectory.hpp"
#include "rigcal/core/time.hpp"

namespace rigcal::calib {

/// The 7 calibration parameters, in lidar_align's order (x, y, z, rotation, time offset).
enum class LidarPoseParam { kX, kY, kZ, kRoll, kPitch, kYaw, kTimeOffset };
inline constexpr std::size_t kLidarPoseParams = 7;
const char* lidarPoseParamName(LidarPoseParam p);

struct ObservabilitySettings {
  double min_rotation_range_deg = 5.0;
  /// z needs more: an error dz only moves points sideways by dz·sin(tilt). On the simulated pose
  /// scenario (VLP-16, 2 cm range noise, 1 % of the returns) the largest roll/pitch range gave z errors
  /// of 3.5–13 cm at 12°, 1–2.4 cm at 29° and under 0.8 cm at 36°.
  double min_tilt_range_for_z_deg = 25.0;
  double min_path_length_m = 1.0;
  double min_speed_range_mps = 0.5;
};

struct ObservabilityReport {
  double duration_s = 0.0;
  std::size_t poses = 0;                           // poses inside the assessed time range
  std::array<double, 3> rotation_range_deg{};      // about pose x, y, z
  std::array<double, 3> angular_rate_rms_dps{};    // about pose x, y, z
  double path_length_m = 0.0;
  double speed_min_mps = 0.0, speed_max_mps = 0.0;
  std::array<bool, kLidarPoseParams> poorly_constrained{};
  std::array<std::string, kLidarPoseParams> reason;  // why, for each flagged parameter

  [[nodiscard]] bool flagged(LidarPoseParam p) const {
    return poorly_constrained[static_cast<std::size_t>(p)];
  }
  /// Human-readable, one line per metric and per flagged parameter.
  [[nodiscard]] std::string text() const;
};

/// Assesses the poses with stamps in [begin, end] (plus the poses bracketing it).
ObservabilityReport assessObservability(const PoseTrajectory& trajectory, TimeNs begin, TimeNs end,
                                        const ObservabilitySettings& settings = {});

}  // namespace rigcal::calib
