#pragma once
// Lidar-to-pose-sensor calibration with time offset (the lidar_align successor).
//
// Stages, as lidar_align (same parameters and defaults):
//  1. global: NLopt GN_DIRECT_L over the rotation only, each rotation-vector component in ±π around the
//     initial rotation (R = exp(δ)·R_initial), translation and time offset at their initial values,
//     neighbour cap global_knn_max_dist (m²). Skipped when `local` is set.
//  2. local: NLopt LN_BOBYQA over x, y, z (initial ± translation_range), rotation (exp(δ)·R_global,
//     δ ∈ ±angular_range) and the time offset (± max_time_offset), cap local_knn_max_dist (m²).
// Each NLopt run stops at max_evals evaluations or xtol. Everything is deterministic: the same input
// gives a bit-identical result on every run and for any thread count.
// Better than lidar_align:
//  - parameters the motion does not excite (lidar_pose_observability.hpp) are held at their initial
//    value and reported instead of being returned as noise;
//  - coarse_local_stage (default on): stage 2 first runs at the global cap, then at the local one.
//    Stage 1 leaves the translation at its initial value, and a lever arm more than ~sqrt(0.1) m from
//    it is outside the local cap's basin: lidar_align's local stage then stops in a wrong minimum
//    (on our synthetic rig, z 33–48 cm off with 1 % of the points).
#include <array>
#include <string>
#include <vector>

#include "rigcal/calib/lidar_pose/lidar_pose_observability.hpp"
#include "rigcal/calib/lidar_pose/lidar_pose_points.hpp"
#include "rigcal/calib/lidar_pose/pose_trajectory.hpp"
#include "rigcal/core/pose.hpp"
#include "rigcal/core/scan.hpp"

namespace rigcal::calib {

/// lidar_align's Aligner::Config (names kept; inital_guess is split into a pose and an offset).
struct LidarPoseSettings {
  LidarPointSelection selection;
  bool local = false;                            // skip the global stage
  Pose initial_T_pose_lidar = Pose::Identity();  // inital_guess (x, y, z, rotation)
  double initial_time_offset_s = 0.0;            // inital_guess (time offset)
  double max_time_offset = 0.1;                  // s
  double angular_range = 0.5;                    // rad, local stage, around the global result
  double translation_range = 1.0;                // m, local stage, around the initial translation
  int max_evals = 200;                           // per stage
  double xtol = 0.0001;
  double local_knn_max_dist = 0.1;   // m² (a squared distance, as in lidar_align)
  double global_knn_max_dist = 1.0;  // m²
  bool time_cal = true;              // estimate the time offset
  int threads = 2;
  ObservabilitySettings observability;
  bool coarse_local_stage = true;  // run stage 2 at the global cap first (see above)
  bool hold_poorly_constrained = true;  // false: optimise them anyway (lidar_align's behaviour)
  std::size_t min_points = 100;         // fewer usable points is an error
};

struct LidarPoseResult {
  Pose T_pose_lidar = Pose::Identity();  // maps lidar points into the pose-sensor frame
  double time_offset_s = 0.0;            // add to lidar timestamps to get pose-sensor time
  Pose global_T_pose_lidar = Pose::Identity();  // after stage 1

  double initial_cost = 0.0;  // at the initial guess, local cap
  double global_cost = 0.0;   // best of stage 1 (global cap); 0 when skipped
  double final_cost = 0.0;    // best of stage 2 (local cap)
  std::size_t global_evaluations = 0, coarse_evaluations = 0, local_evaluations = 0;  // local includes coarse
  std::string global_status = "skipped", coarse_status = "skipped", local_status = "skipped";  // NLopt

  double select_seconds = 0.0, global_seconds = 0.0, local_seconds = 0.0, total_seconds = 0.0;

  ObservabilityReport observability;
  std::array<bool, kLidarPoseParams> held{};  // parameters kept at the initial guess
  LidarPoints points;                         // the returns used (for the fused cloud)
};

/// Restricts `points` to the trajectory (± max_time_offset; throws naming both time ranges when fewer
/// than min_points remain), assesses observability and runs both stages.
LidarPoseResult calibrateLidarPose(LidarPoints points, const PoseTrajectory& trajectory,
                                   const LidarPoseSettings& settings);
/// Selects the returns of decoded scans (absolute point time = stamp_ns + offset_ns), then as above.
LidarPoseResult calibrateLidarPose(const std::vector<Scan>& scans, const PoseTrajectory& trajectory,
                                   const LidarPoseSettings& settings);

}  // namespace rigcal::calib
