#pragma once
// Everything one calibration run produced, in one place for the writers (calibration.yaml, report.json,
// clouds, overview.png, the stdout summary).
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "rigcal/calib/base_lidar/base_from_motion.hpp"
#include "rigcal/calib/base_lidar/base_lidar_calibration.hpp"
#include "rigcal/calib/lidar_lidar/lidar_lidar_calibration.hpp"
#include "rigcal/core/pose.hpp"
#include "rigcal/core/scan.hpp"
#include "rigcal/pipeline/calibration_dataset.hpp"

namespace rigcal::calib {

struct CalibrationOutcome {
  std::string rig_name;
  std::string base_frame = "base_link";
  std::string mapping_sensor;
  std::string version;                                // rigcal's
  std::map<std::string, Pose> initial_T_base_sensor;  // every sensor of the rig, from its config
  std::optional<BaseLidarResult> base;                // when base-lidar calibration ran
  /// When base_link_from_motion is on and the ground succeeded: yaw / x from the drive, already in
  /// base->T_base_lidar.
  std::optional<BaseFromMotionResult> base_motion;
  std::string base_skipped;                           // why base-lidar calibration did not run (empty: it ran)
  std::vector<pipeline::CalibrationDataset> datasets; // one per calibration lidar (may lack a result)
  std::vector<LidarLidarResult> lidars;               // one per dataset that was calibrated
  /// The mapper's whole map (map frame, already voxelised): map.pcd and the overview draw it as it is.
  /// Null when the caller has none (then the datasets' mapping clouds are aggregated instead).
  std::shared_ptr<const Scan> map_cloud;
  double deadline_s = 0.0;
  /// Why the run as a whole has no result (not enough data, interrupted); empty when it produced one.
  /// calibration.yaml then holds this failure and no extrinsic, never the initial guess as if calibrated.
  std::string failure;
  std::vector<std::pair<std::string, double>> stage_seconds;  // whole-run stages (pipeline, calibration, outputs)
  std::vector<std::pair<std::string, std::string>> input_summary;  // source, scans, keyframes, ...
  std::vector<std::string> warnings;  // damaged input (packets lost, malformed, a truncated capture): one line each

  /// T_base_mapping: the base-lidar result when it succeeded, else the initial one.
  [[nodiscard]] Pose T_base_mapping() const;
  /// Every sensor's T_base_sensor: calibrated where a calibration succeeded, else initial.
  [[nodiscard]] std::map<std::string, Pose> T_base_sensor() const;
  /// "failed" (failure set, or a calibration failed), "unverified" (a result not confirmed), else "ok".
  [[nodiscard]] std::string status() const;
  /// The lidar-lidar result of `sensor`, or nullptr.
  [[nodiscard]] const LidarLidarResult* lidar(const std::string& sensor) const;
};

}  // namespace rigcal::calib
