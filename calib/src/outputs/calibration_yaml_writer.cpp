#include "rigcal/calib/outputs/calibration_yaml_writer.hpp"
#include "rigcal/core/atomic_file.hpp"

#include <fstream>
#include <iomanip>
#include <sstream>
#include <stdexcept>

namespace rigcal::calib {
namespace {

void writeXyzRpy(std::ostream& out, const std::string& indent, const Pose& T) {
  const XyzRpy v = toXyzRpy(T);
  out << std::fixed << std::setprecision(6);
  out << indent << "x: " << v.x << "\n" << indent << "y: " << v.y << "\n" << indent << "z: " << v.z << "\n";
  out << indent << "roll: " << v.roll << "\n" << indent << "pitch: " << v.pitch << "\n" << indent << "yaw: " << v.yaw << "\n";
}

/// A YAML double-quoted scalar (the failure text may hold quotes, colons or backslashes).
std::string quoted(const std::string& text) {
  std::string q = "\"";
  for (const char c : text) {
    if (c == '"' || c == '\\') q += '\\';
    q += c == '\n' ? ' ' : c;
  }
  return q + "\"";
}

std::string failedCalibrationYaml(const CalibrationOutcome& o) {
  std::ostringstream out;
  out << "# rigcal " << o.version << ": the calibration of rig '" << o.rig_name
      << "' FAILED; this file holds no extrinsic (see report.json)\n"
      << "status: failed\nfailure: " << quoted(o.failure) << "\n";
  return out.str();
}

std::string lidarComment(const LidarLidarResult& r) {
  if (!r.ok) return "  # not calibrated: the initial guess";
  if (r.verdict == Verdict::kUnverified) return "  # unverified: " + r.doubt;
  return "";
}

}  // namespace

std::string calibrationYaml(const CalibrationOutcome& o) {
  if (!o.failure.empty()) return failedCalibrationYaml(o);
  std::ostringstream out;
  out << "# rigcal " << o.version << " calibration of rig '" << o.rig_name << "'\n"
      << "# parent:\n#   child: T_parent_child as x y z (m) roll pitch yaw (rad), R = Rz(yaw)*Ry(pitch)*Rx(roll)\n"
      << "# status: ok = every result confirmed; unverified / failed: see the comments and report.json\n"
      << "status: " << o.status() << "\n";
  if (!o.base && !o.base_skipped.empty())
    out << "# " << o.base_frame << " -> " << o.mapping_sensor << ": not calibrated (" << o.base_skipped
        << "): the initial extrinsic\n";
  // base_link -> mapping lidar (the base-lidar calibration: z, roll, pitch from the ground).
  out << o.base_frame << ":\n  " << o.mapping_sensor << ":\n";
  writeXyzRpy(out, "    ", o.T_base_mapping());
  // mapping lidar -> each calibration lidar (the lidar-lidar calibration).
  if (!o.lidars.empty()) {
    out << o.mapping_sensor << ":\n";
    for (const auto& r : o.lidars) {
      out << "  " << r.calibration_sensor << ":" << lidarComment(r) << "\n";
      writeXyzRpy(out, "    ", r.ok ? r.T_mapping_calib : r.T_mapping_calib_guess);
    }
  }
  out << "# every sensor in " << o.base_frame << "\nT_base_sensor:\n";
  for (const auto& [name, T] : o.T_base_sensor()) {
    const LidarLidarResult* r = o.lidar(name);
    out << "  " << name << ":" << (r != nullptr ? lidarComment(*r) : "") << "\n";
    writeXyzRpy(out, "    ", T);
  }
  return out.str();
}

void writeCalibrationYaml(const std::filesystem::path& path, const CalibrationOutcome& outcome) {
  writeFileAtomically(path, [&](std::ostream& out) { out << calibrationYaml(outcome); });
}

std::string lidarPoseYaml(const LidarPoseResult& r, const std::string& parent_frame, const std::string& child_frame) {
  std::string flagged;
  for (std::size_t i = 0; i < kLidarPoseParams; ++i)
    if (r.observability.poorly_constrained[i])
      flagged += std::string(flagged.empty() ? "" : ", ") + lidarPoseParamName(static_cast<LidarPoseParam>(i));
  std::ostringstream out;
  out << "# rigcal calibrate-pose: T_" << parent_frame << "_" << child_frame << " (maps " << child_frame
      << " points into the " << parent_frame << " frame)\n"
      << "# poorly constrained by the motion" << (flagged.empty() ? "" : " (held at the initial guess unless disabled)")
      << ": " << (flagged.empty() ? "none" : flagged) << "\n"
      << parent_frame << ":\n  " << child_frame << ":\n";
  writeXyzRpy(out, "    ", r.T_pose_lidar);
  out << std::setprecision(9) << "    time_offset_s: " << r.time_offset_s << "\n";
  return out.str();
}

void writeLidarPoseYaml(const std::filesystem::path& path, const LidarPoseResult& result,
                        const std::string& parent_frame, const std::string& child_frame) {
  writeFileAtomically(path, [&](std::ostream& out) { out << lidarPoseYaml(result, parent_frame, child_frame); });
}

}  // namespace rigcal::calib
