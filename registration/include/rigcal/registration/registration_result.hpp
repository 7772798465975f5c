#pragma once
// What every registration returns.
#include <cstddef>
#include <string>
#include <string_view>

#include "rigcal/core/pose.hpp"

namespace rigcal::registration {

enum class Status {
  kConverged,              // the last update was below the epsilons
  kMaxIterations,          // ran out of iterations; the pose is the last iterate
  kTimeout,                // the deadline passed; the pose is the best fully evaluated one
  kCancelled,              // the cancel token was set; likewise
  kDegenerate,             // converged, but the geometry leaves some direction unconstrained
  kTooFewCorrespondences,  // fewer than min_correspondences matches (no overlap, or guess too far off)
  kInvalidInput,           // empty / non-finite clouds or guess, missing target structure, bad parameter
};

std::string_view toString(Status status);

struct RegistrationResult {
  Pose T_target_source = Pose::Identity();  // maps source points into the target frame; never NaN
  int iterations = 0;
  bool converged = false;
  // Nearest-neighbour quality at T_target_source, within the method's max_correspondence_distance d
  // (see evaluator.hpp): rmse over inliers (d when there are none), inlier_ratio = inliers / source
  // points, fitness = mean over all source points of min(dist², d²) in m² (lower is better).
  double rmse = 0.0;
  double inlier_ratio = 0.0;
  double fitness = 0.0;
  std::size_t inliers = 0;
  // Smallest / largest eigenvalue of the normalised point-to-plane information (translation in m,
  // rotation scaled by the cloud's radius) at the result; near 0 means a degenerate direction. −1 if
  // not computed.
  double conditioning = -1.0;
  Status status = Status::kInvalidInput;
  std::string reason;  // one line, why it ended this way

  /// Converged on well-constrained geometry.
  [[nodiscard]] bool ok() const { return status == Status::kConverged; }
};

}  // namespace rigcal::registration
