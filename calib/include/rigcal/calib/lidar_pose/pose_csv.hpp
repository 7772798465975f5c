#pragma once
// Stamped 6-DOF poses from a CSV file in lidar_align's (maplab's) layout:
//   timestamp_ns, index, px, py, pz, qw, qx, qy, qz
// Lines starting with '#' and blank lines are skipped; every other line must be a valid pose.
// Unlike lidar_align (which silently skips short lines and throws from std::stoll), every malformed
// line is an error "file:line: what".
#include <filesystem>
#include <istream>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "rigcal/core/pose.hpp"
#include "rigcal/core/time.hpp"

namespace rigcal::calib {

struct PoseCsvOptions {
  /// Poses whose first position has a coordinate larger than this (metres, e.g. UTM) are re-centred:
  /// the first position, rounded to whole metres, is subtracted from every position so the fused cloud
  /// keeps float precision. A negative value disables re-centring.
  double recentre_above_m = 1000.0;
  /// Largest accepted | |q| − 1 | before a quaternion is rejected (accepted ones are normalised).
  double quaternion_norm_tolerance = 1e-3;
  /// Largest accepted coordinate (metres): covers ECEF and UTM, refuses 1e300 and such.
  double max_abs_position_m = 1e8;
  /// Largest accepted speed between consecutive poses (m/s, 720 km/h), plus a jump allowance for a
  /// GNSS fix that snaps back (RTK float to fixed) at any rate: a larger jump is a broken row.
  double max_speed_mps = 200.0;
  double jump_allowance_m = 2.0;
};

struct PoseCsv {
  std::vector<TimeNs> stamps;  // strictly increasing
  std::vector<Pose> poses;     // T_world_pose with `origin` subtracted from the translation
  /// What was subtracted from every position (zero when not re-centred): world = pose + origin.
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  std::size_t skipped_lines = 0;  // comments and blank lines
};

/// Throws std::runtime_error "<name>:<line>: <what>" on the first malformed line, and "<name>: ..."
/// when the file cannot be read or holds no pose.
PoseCsv parsePoseCsv(std::istream& in, const std::string& name, const PoseCsvOptions& options = {});
PoseCsv readPoseCsv(const std::filesystem::path& path, const PoseCsvOptions& options = {});

}  // namespace rigcal::calib
