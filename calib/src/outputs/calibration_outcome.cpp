#include "rigcal/calib/outputs/calibration_outcome.hpp"

namespace rigcal::calib {

Pose CalibrationOutcome::T_base_mapping() const {
  if (base && base->ok) return base->T_base_lidar;
  const auto it = initial_T_base_sensor.find(mapping_sensor);
  return it == initial_T_base_sensor.end() ? Pose::Identity() : it->second;
}

std::map<std::string, Pose> CalibrationOutcome::T_base_sensor() const {
  std::map<std::string, Pose> out = initial_T_base_sensor;
  const Pose T_base_mapping_final = T_base_mapping();
  if (!mapping_sensor.empty()) out[mapping_sensor] = T_base_mapping_final;
  // A calibration lidar hangs off the mapping lidar: re-anchor it on the (possibly recalibrated) base.
  for (const auto& r : lidars) out[r.calibration_sensor] = T_base_mapping_final * (r.ok ? r.T_mapping_calib : r.T_mapping_calib_guess);
  return out;
}

std::string CalibrationOutcome::status() const {
  bool unverified = false;
  for (const auto& r : lidars) {
    if (r.verdict == Verdict::kFailed) return "failed";
    unverified = unverified || r.verdict == Verdict::kUnverified;
  }
  if (!failure.empty() || (base && !base->ok)) return "failed";
  return unverified ? "unverified" : "ok";
}

const LidarLidarResult* CalibrationOutcome::lidar(const std::string& sensor) const {
  for (const auto& r : lidars)
    if (r.calibration_sensor == sensor) return &r;
  return nullptr;
}

}  // namespace rigcal::calib
