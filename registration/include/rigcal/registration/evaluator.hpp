#pragma once
// How well a source cloud sits on a target under a pose: each source point's nearest target point,
// inliers within max_distance. Unlike upstream's score it has an inlier term (a pose that pushes most
// points out of range cannot look good) and it is defined when nothing corresponds (no NaN).
#include <cstddef>
#include <span>

#include "rigcal/core/pose.hpp"
#include "rigcal/registration/point_cloud.hpp"
#include "rigcal/registration/target.hpp"

namespace rigcal::registration {

struct Evaluation {
  std::size_t points = 0;   // source points evaluated
  std::size_t inliers = 0;  // with a target point within max_distance
  double mean_sq_distance = 0.0;  // m², over inliers; max_distance² when there are none
  double rmse = 0.0;              // sqrt(mean_sq_distance)
  double inlier_ratio = 0.0;      // inliers / points; 0 for an empty source
  double fitness = 0.0;           // m², mean over all points of min(dist², max_distance²); lower is better
};

/// Throws std::invalid_argument unless max_distance is finite and > 0.
Evaluation evaluate(const Target& target, const PointCloud& source, const Pose& T_target_source,
                    double max_distance, int num_threads = 1);
/// Over several pairs under one pose (the batched-ICP objective), counted as one cloud.
Evaluation evaluate(std::span<const SourceTarget> pairs, const Pose& T_target_source, double max_distance,
                    int num_threads = 1);

/// Fills the derived fields of `e` from points, inliers and the inliers' summed squared distance.
void finishEvaluation(Evaluation& e, double sum_sq_distance, double max_distance);

}  // namespace rigcal::registration
