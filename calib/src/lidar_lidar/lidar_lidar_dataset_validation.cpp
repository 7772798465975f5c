// What a CalibrationDataset must hold before calibration starts: one clear message for the first gap.
#include <sstream>

#include "rigcal/calib/lidar_lidar/lidar_lidar_calibration.hpp"
#include "lidar_lidar_calibrator.hpp"

namespace rigcal::calib {

using detail::finitePose;

std::string validateDataset(const pipeline::CalibrationDataset& d, const config::Parameters& params) {
  std::ostringstream msg;
  const std::string who = d.calibration_sensor.empty() ? std::string("<unnamed>") : d.calibration_sensor;
  if (d.calibration_sensor.empty()) return "calibration dataset: calibration_sensor is empty";
  if (!finitePose(d.T_mapping_calib_guess)) return who + ": T_mapping_calib_guess is not finite";
  if (d.frames.empty()) return who + ": no selected calibration frames";
  if (int(d.frames.size()) < params.lidar_calibration_min_frames) {
    msg << who << ": " << d.frames.size() << " of " << params.lidar_calibration_min_frames
        << " frames needed (lidar_calibration_min_frames)";
    return msg.str();
  }
  if (d.trajectory.size() < 2) return who + ": the mapping trajectory has fewer than two poses";
  for (std::size_t i = 1; i < d.trajectory.size(); ++i)
    if (d.trajectory[i].stamp_ns <= d.trajectory[i - 1].stamp_ns) {
      msg << who << ": mapping trajectory stamps not increasing at index " << i;
      return msg.str();
    }
  if (d.mapping_clouds.empty()) return who + ": no mapping clouds around the selected keyframes";
  for (std::size_t i = 0; i < d.mapping_clouds.size(); ++i)
    if (d.mapping_clouds[i].cloud == nullptr || !finitePose(d.mapping_clouds[i].frame.T_map_lidar)) {
      msg << who << ": mapping_clouds[" << i << "] has no cloud or a non-finite pose";
      return msg.str();
    }
  for (std::size_t i = 0; i < d.frames.size(); ++i) {
    const auto& f = d.frames[i];
    if (f.raw == nullptr || f.deskewed == nullptr) {
      msg << who << ": frames[" << i << "] has no " << (f.raw == nullptr ? "raw" : "deskewed") << " scan";
      return msg.str();
    }
    if (!finitePose(f.pairing.T_map_mapping_at_scan)) {
      msg << who << ": frames[" << i << "].pairing.T_map_mapping_at_scan is not finite";
      return msg.str();
    }
    if (f.pairing.keyframe_frame >= d.trajectory.size() || d.trajectory[f.pairing.keyframe_frame].keyframe_index < 0) {
      msg << who << ": frames[" << i << "].pairing.keyframe_frame " << f.pairing.keyframe_frame
          << " is not a keyframe of the trajectory";
      return msg.str();
    }
    for (const std::size_t c : f.window)
      if (c >= d.mapping_clouds.size()) {
        msg << who << ": frames[" << i << "].window names mapping cloud " << c << " of " << d.mapping_clouds.size();
        return msg.str();
      }
  }
  return {};
}

}  // namespace rigcal::calib
