#include "rigcal/calib/calibration_yaml_writer.hpp"
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

}  // namespace

std::string calibrationYaml(const CalibrationOutcome& o) {
  std::ostringstream out;
  out << "# rigcal " << o.version << " calibration of rig '" << o.rig_name << "'\n"
      << "# parent:\n#   child: T_parent_child as x y z (m) roll pitch yaw (rad), R = Rz(yaw)*Ry(pitch)*Rx(roll)\n";
  // base_link -> mapping lidar (the base-lidar calibration: z, roll, pitch from the ground).
  out << o.base_frame << ":\n  " << o.mapping_sensor << ":\n";
  writeXyzRpy(out, "    ", o.T_base_mapping());
  // mapping lidar -> each calibration lidar (the lidar-lidar calibration).
  if (!o.lidars.empty()) {
    out << o.mapping_sensor << ":\n";
    for (const auto& r : o.lidars) {
      out << "  " << r.calibration_sensor << ":" << (r.ok ? "" : "  # not calibrated: the initial guess") << "\n";
      writeXyzRpy(out, "    ", r.ok ? r.T_mapping_calib : r.T_mapping_calib_guess);
    }
  }
  out << "# every sensor in " << o.base_frame << "\nT_base_sensor:\n";
  for (const auto& [name, T] : o.T_base_sensor()) {
    out << "  " << name << ":\n";
    writeXyzRpy(out, "    ", T);
  }
  return out.str();
}

void writeCalibrationYaml(const std::filesystem::path& path, const CalibrationOutcome& outcome) {
  writeFileAtomically(path, [&](std::ostream& out) { out << calibrationYaml(outcome); });
}

}  // namespace rigcal::calib
