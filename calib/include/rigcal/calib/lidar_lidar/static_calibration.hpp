#pragma once
// Static calibration (`rigcal calibrate --static`): the vehicle stands still, every lidar's sweeps over
// static_capture_s are accumulated in its own frame (no deskew: nothing moves), and each calibration
// lidar's accumulated cloud is registered straight to the mapping lidar's with the cloud-pair path of
// `rigcal register` (global stage, the lidar-lidar ensemble and its score, overlap and information);
// base-lidar comes from the ground under the mapping lidar as in a driving calibration. The outputs are
// those of a driving calibration (CalibrationOutcome), with the same verdict rules plus two of its own:
// a result the scene leaves poorly constrained (named directions) or whose global basin is not unique is
// never `ok`.
//
// Stillness: every mapping-lidar sweep of the capture is registered (point-to-plane ICP) to the first;
// the vehicle stood still when none is further than static_max_motion_m / static_max_motion_deg from it.
#include <cstddef>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "rigcal/calib/outputs/calibration_outcome.hpp"
#include "rigcal/calib/lidar_lidar/cloud_pair_registration.hpp"
#include "rigcal/config/rig_config.hpp"
#include "rigcal/core/scan.hpp"

namespace rigcal::calib {

using ScanList = std::vector<std::shared_ptr<const Scan>>;

/// Where one mapping sweep was against the first of the capture.
struct StillnessSample {
  std::size_t scan = 0;     // index in the capture (0 = the first)
  double t_s = 0.0;         // seconds after the first sweep's stamp
  double metres = 0.0;      // translation from the first sweep's pose
  double degrees = 0.0;     // rotation from it
};

struct StillnessCheck {
  bool still = true;
  std::vector<StillnessSample> samples;        // one per sweep after the first
  std::optional<StillnessSample> first_moved;  // the first sweep over the limits
  StillnessSample largest;                     // the largest motion (by metres, then degrees)
  double limit_m = 0.0, limit_deg = 0.0;
  double seconds = 0.0;
  /// One line when !still: when and how much ("... 1.30 s into the capture (sweep 14) the mapping lidar
  /// was 0.42 m / 3.1 deg from where it started ...").
  std::string message;
};

/// Registers every sweep to the first (ICP on voxelised clouds, from the identity: standing still, the
/// identity is right). Needs at least one sweep; with one it is trivially still.
StillnessCheck checkStillness(const ScanList& mapping_scans, const config::Parameters& params);

/// The sweeps as one cloud in the sensor's frame, voxelised at `voxel` (centroids: the sweeps' noise
/// averages out); stamp of the first sweep.
Scan accumulateSweeps(const ScanList& scans, double voxel);

/// What the command gives the calibration: each sensor's sweeps within the capture window.
struct StaticCapture {
  ScanList mapping;
  std::vector<std::pair<std::string, ScanList>> calibration;  // per calibration lidar, rig order
  double capture_s = 0.0;                                      // the window's length as captured
};

struct StaticCalibrationOptions {
  double deadline_s = 10.0;  // calibration_deadline_s: the whole calibration (after the capture)
  /// Share of the deadline kept for what follows the ensembles (the final polish, information and
  /// shared-floor refinement of each lidar, base-lidar): the global stages and ensembles of all the
  /// calibration lidars share the rest.
  double later_share = 0.2;
  int num_threads = 2;
  /// A second basin whose score is within this factor of the best one makes the result ambiguous.
  double min_uniqueness = 1.25;
};

struct StaticCalibration {
  StillnessCheck stillness;
  std::vector<std::pair<std::string, CloudPairResult>> pairs;  // per calibration lidar
  CalibrationOutcome outcome;  // ready for the writers; failure set when nothing could be calibrated
};

/// Never throws for bad data. A capture in which the vehicle moved gives stillness.still = false and no
/// calibration (outcome.failure holds stillness.message).
StaticCalibration calibrateStatic(const StaticCapture& capture, const config::RigConfig& rig,
                                  const StaticCalibrationOptions& options);

}  // namespace rigcal::calib
