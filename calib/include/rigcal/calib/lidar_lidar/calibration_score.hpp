#pragma once
// The ensemble's yardstick: how well the calibration clouds of all selected frames sit on their
// augmented targets under one extrinsic. Upstream scores the mean squared distance of the points that
// have a neighbour within calibration_eval_max_corr_distance, so a pose that pushes most points out of
// range looks good and nothing-in-range gives NaN. Ours is the mean over ALL points of
// min(d², d_max²): an outlier costs d_max², so the inlier share is part of the score; it is finite always.
#include <cstddef>
#include <vector>

#include "rigcal/core/pose.hpp"
#include "rigcal/registration/point_cloud.hpp"
#include "rigcal/registration/target.hpp"

namespace rigcal::calib {

struct CalibrationScore {
  double value = 0.0;  // m², mean over points of min(d², d_max²); lower is better
  double rmse = 0.0;   // m, over inliers (d_max when there are none)
  double inlier_ratio = 0.0;
  std::size_t points = 0;
  std::size_t inliers = 0;
  [[nodiscard]] bool betterThan(const CalibrationScore& other) const { return value < other.value; }
};

/// One frame's score (all of its source points).
CalibrationScore scoreFrame(const registration::Target& target, const registration::PointCloud& source,
                            const Pose& T_mapping_calib, double max_distance, int num_threads = 1);

/// The score over all frames, each frame's points weighted equally (so a frame counts by its size).
/// `stride` > 1 scores every stride-th point of each source (deterministic), to bound its cost.
CalibrationScore scoreAllFrames(const std::vector<registration::SourceTarget>& frames, const Pose& T_mapping_calib,
                                double max_distance, std::size_t stride = 1, int num_threads = 1);

/// The stride that keeps scoreAllFrames under about `max_points` points.
std::size_t scoreStride(const std::vector<registration::SourceTarget>& frames, std::size_t max_points);

}  // namespace rigcal::calib
