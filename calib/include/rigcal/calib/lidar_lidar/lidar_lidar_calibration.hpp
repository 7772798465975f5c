#pragma once
// Lidar-lidar calibration of one calibration lidar against the mapping lidar's dense map, from the
// pipeline's CalibrationDataset, in bounded time. See ensemble_plan.hpp for the order of the work,
// calibration_score.hpp for the score, augmented_target.hpp / calibration_source.hpp for the clouds.
#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "rigcal/calib/lidar_lidar/augmented_target.hpp"
#include "rigcal/calib/lidar_lidar/calibration_score.hpp"
#include "rigcal/calib/lidar_lidar/frame_pose_information.hpp"
#include "rigcal/calib/lidar_lidar/trajectory_time_offset.hpp"
#include "rigcal/config/parameters.hpp"
#include "rigcal/core/pose.hpp"
#include "rigcal/pipeline/calibration_dataset.hpp"
#include "rigcal/registration/deadline.hpp"

namespace rigcal::calib {

struct LidarLidarOptions {
  int num_threads = 2;                // per registration, target build and score (results do not depend on it)
  AugmentedTargetOptions target;      // its num_threads is overridden by the one above
  std::size_t score_points = 60000;   // points (over all frames) the all-frames score looks at
  bool redeskew = true;               // re-deskew with the calibrated extrinsic before the final registration
  /// After the quick passes and the final refinement, spend the time left on upstream's exhaustive
  /// ensemble (every registrator from every candidate on every frame). Off: finish as soon as refined.
  bool exhaustive = true;
  /// The share of the time a complete plan left that the searches for another basin (the batched chain from
  /// the guess, the exhaustive ensemble) may use; the rest goes unused, to the lidars still to come
  /// (LidarLidarWorker sets 0 while others wait: the street's first lidar filled its whole share with them
  /// while the second one's plan was cut).
  double search_share = 1.0;
  /// After the plan, the residual clock offset against the mapping trajectory from the frames just
  /// registered (trajectory_time_offset.hpp). Under a deadline the plan leaves it the time it is expected to
  /// take from a timed score (at first `trajectory_clock_share` of the share; at most `trajectory_clock_max_s`);
  /// it runs before the searches for another basin, and again should they find a better result.
  bool trajectory_clock = false;
  double trajectory_clock_share = 0.15;
  double trajectory_clock_max_s = 2.0;
  TrajectoryClockOptions trajectory_clock_options;
};

/// One registration the ensemble ran (for report.json).
struct RegistratorRun {
  int frame = -1;             // dataset frame index; −1 = batched over all frames
  std::string registrator;    // ndt, gicp, icp_coarse, icp_fine, icp_ultra_fine, batched_icp
  double max_distance = 0.0;  // correspondence distance (m)
  std::size_t start = 0;      // index into LidarLidarResult::candidates it started from
  std::size_t result = SIZE_MAX;  // index into candidates of its result; SIZE_MAX = none (failed, out of time)
  double seconds = 0.0;
  int iterations = 0;
  std::string status;
  double frame_score = -1.0;  // its own frame's score (m²); −1 = not computed (batched, or out of time)
  double score = -1.0;        // all-frames score (m²); −1 = not computed (not its frame's best)
  // On the frame's source re-deskewed with the best extrinsic (finalStep), as the final result's last
  // registrations were: only these are compared with it by the verdict when the frame has any.
  bool redeskewed = false;
};

/// What a result is worth, judged against its own evidence (lidar_lidar_verdict.hpp): `ok` only when it
/// beats the guess AND frames and registrators agree on it with a sane inlier ratio.
enum class Verdict { kOk, kUnverified, kFailed };

const char* toString(Verdict v);

/// The evidence behind the verdict (report.json's "evidence").
struct LidarLidarEvidence {
  double improvement = 0.0;          // 1 − final/initial score: share of the guess's score removed
  std::size_t frames_selected = 0;   // frames the dataset offered
  std::size_t frames_registered = 0; // frames that got at least one scored per-frame registration
  std::size_t frames_agreeing = 0;   // of those, frames whose own best result lies near the final one
  double frame_spread_m = 0.0;       // largest distance of a frame's own best result from the final one
  double frame_spread_deg = 0.0;
  // How far the final result may be off, judged by how its frames scatter about it: two standard errors
  // over the own best results of the n frames that agree with it (2 · rms / sqrt(n) when they weigh alike;
  // an outlier frame counts against the result as a disagreeing frame instead); 0 with fewer than two.
  double frame_uncertainty_m = 0.0;
  double frame_uncertainty_deg = 0.0;
  // Each frame's deviation weighted in each direction by its information over its score and by how far its
  // equally good runs spread (result.frame_information; see lidar_lidar_verdict.cpp): false when some agreeing
  // frame has no information, then every frame counts alike.
  bool frame_uncertainty_weighted = false;
  std::vector<std::string> registrators_agreeing;  // registrators with a result near the final one
  double inlier_ratio = 0.0;         // of the final score
  double suggested_deadline_s = 0.0; // > 0: the calibration_deadline_s (--deadline) that would confirm it
  double clock_offset_ms = 0.0;      // its packet clock against the mapping lidar's (both vs capture time)
  double clock_offset_uncertainty_ms = 0.0;  // one standard error of clock_offset_ms
  bool clock_measured = false;       // both clocks were measured (else clock_offset_ms says nothing)
  double time_offset_applied_ms = 0.0;  // the rig's time_offset_ns (given or estimated) already subtracted
};

struct LidarLidarResult {
  std::string mapping_sensor;
  std::string calibration_sensor;
  bool ok = false;               // the result beats the initial guess's score
  std::string failure;           // one line when !ok
  bool deadline_reached = false; // stopped by the deadline (or a cancel): the best so far
  double deadline_share_s = -1.0; // seconds it was given when it started (its share); −1 = no limit
  Pose T_mapping_calib_guess = Pose::Identity();
  Pose T_mapping_calib = Pose::Identity();  // the best found (the guess when nothing beat it)
  CalibrationScore initial_score;
  CalibrationScore final_score;
  std::vector<std::size_t> frames_used;       // dataset frame indices that had a target
  std::vector<std::string> frames_skipped;    // "frame 3: <why>"
  // Dataset frames registered but left out of the final score and batched ICP: their own re-deskewed
  // registration disagreed with the result while a majority agreed (the verdict counts them as disagreeing).
  std::vector<std::size_t> frames_set_aside;
  std::vector<Pose> candidates;               // [0] = the initial guess
  std::vector<RegistratorRun> runs;
  std::vector<std::pair<std::string, double>> stage_seconds;  // targets, ensemble, batched, redeskew+final
  double seconds = 0.0;
  Verdict verdict = Verdict::kFailed;  // kOk needs ok and the evidence; kUnverified: ok but not confirmed
  std::string doubt;                   // one line when verdict is kUnverified: why, and what is missing
  LidarLidarEvidence evidence;
  // Per dataset frame registered: its information at the result, on the sources the result was refined on
  // (frame_pose_information.hpp, over the whole frame), which weights the frame's scatter in the verdict.
  // Empty: weighted equally.
  std::map<int, PoseInformation> frame_information;
  TrajectoryClockEstimate trajectory_clock;  // kNotRun unless LidarLidarOptions::trajectory_clock
};

/// Empty when `dataset` can be calibrated, else one line naming the field that is wrong.
std::string validateDataset(const pipeline::CalibrationDataset& dataset, const config::Parameters& params);

/// Never throws for bad data: an invalid dataset gives ok = false with the reason. Stops by `deadline`;
/// a failure because it ran out of time starts with "deadline:".
LidarLidarResult calibrateLidarLidar(const pipeline::CalibrationDataset& dataset, const config::Parameters& params,
                                     const registration::Deadline& deadline, const LidarLidarOptions& options = {});

/// calibrateLidarLidar for an owner of `dataset` that needs none of its mapping clouds afterwards
/// (LidarLidarWorker without keep_mapping_clouds): each cloud is reset as soon as the last target built from
/// it exists (dropMappingCloudsDoneWith), the rest when the calibration ends. The same result.
LidarLidarResult calibrateLidarLidarDroppingClouds(pipeline::CalibrationDataset& dataset, const config::Parameters& params,
                                                   const registration::Deadline& deadline,
                                                   const LidarLidarOptions& options = {});

}  // namespace rigcal::calib
