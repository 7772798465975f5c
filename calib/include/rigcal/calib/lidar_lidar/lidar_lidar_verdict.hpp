#pragma once
// The quality gate of a lidar-lidar result. Beating the guess's score is not enough to call a result ok:
// a side-mounted lidar came out 42 cm off (worse than its guess) with a better score, an inlier ratio of
// 0.49 and 3 of 7 frames registered before the deadline. A result is `ok` only when its own evidence
// confirms it: at least two frames whose own best registration lands near it (and no more frames
// against it than for it), frames that scatter little enough about it that it is within the accuracy
// goal, at least two registrators that reach it, and an inlier ratio that says the clouds really overlap. Otherwise it is `unverified`, with the reason and what is missing (the
// `--deadline` that would do when the deadline cut the plan).
#include <cstddef>

#include "rigcal/calib/lidar_lidar/lidar_lidar_calibration.hpp"

namespace rigcal::calib {

struct VerdictOptions {
  double agree_m = 0.05;      // a result this close to the final one confirms it (per-frame results of a
  double agree_deg = 0.5;     // 16-beam lidar scatter by 1-2 cm / 0.1-0.2°)
  std::size_t min_frames = 2;
  std::size_t min_registrators = 2;
  double min_inlier_ratio = 0.5;  // measured 0.66-0.94 for good results, 0.49 for the 42 cm one
  // The accuracy goal: a result whose frames scatter so much that two standard errors of their mean exceed it
  // cannot be called ok (a rear lidar came out 0.09° off, called ok, its frames scattering 0.10-0.14°).
  double goal_m = 0.01;
  double goal_deg = 0.05;
  // A frame's runs whose scores lie within this share of its best are answers it cannot tell apart: their
  // spread about its best discounts the frame where they differ (lidar_lidar_verdict.cpp).
  double equal_score_share = 0.02;
};

/// Whether a registration's result `T` confirms `result`: within agree_m and agree_deg of it. What the verdict
/// counts as an agreeing frame or registrator, and what the calibration keeps a frame in its objective by.
bool agrees(const Pose& T, const Pose& result, const VerdictOptions& options = {});

/// Fills result.evidence, result.verdict and result.doubt. `frames_selected` is the dataset's frame
/// count, `deadline_s` the calibration_deadline_s the run had (for the suggested --deadline).
void judgeLidarLidar(LidarLidarResult& result, std::size_t frames_selected, double deadline_s,
                     const VerdictOptions& options = {});

/// A lidar whose packet clock is `offset_ms` off the mapping lidar's (each against the capture / receive
/// time) is paired with the wrong mapping pose: 50 ms at walking speed put a lidar 7 cm off with a normal
/// score. Records the offset (± `uncertainty_ms`, one standard error); above `limit_ms` a result is not called
/// ok (the sensor and the offset named, with the rig's time_offset_ns that would correct it).
void doubtClockOffset(LidarLidarResult& result, double offset_ms, double limit_ms, double uncertainty_ms = 0.0);

/// The same judgement from result.trajectory_clock (the offset against the mapping trajectory, which needs
/// no capture time: live and shared-memory input): an estimate beyond `limit_ms` that is significant
/// (|δ| > 2σ) makes the result unverified, naming the sensor, δ ± σ and the time_offset_ns that would fix
/// it. Not |δ| > limit + 2σ: a lidar 35 ms late over shm measured +38.7 ± 15.5 ms and its 3.6 cm error
/// would have passed as ok. An estimate the deadline cut is missing evidence when the packet clocks were not
/// compared either (doubtClockOffset): unverified, with the `--deadline` that would do (from `deadline_s`,
/// the calibration_deadline_s of the run). Unobservable or not run: nothing is judged.
void doubtTrajectoryClockOffset(LidarLidarResult& result, double limit_ms, double deadline_s);

}  // namespace rigcal::calib
