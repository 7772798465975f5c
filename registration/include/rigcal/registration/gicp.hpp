#pragma once
// Generalized ICP (Segal, Haehnel, Thrun 2009): each match is weighted by the inverse of the fused
// covariance C_target + R·C_source·Rᵀ (plane-regularised, so it acts as a symmetric plane-to-plane
// distance). Gauss–Newton with Levenberg–Marquardt safeguarding on SE(3).
#include "rigcal/core/pose.hpp"
#include "rigcal/registration/deadline.hpp"
#include "rigcal/registration/point_cloud.hpp"
#include "rigcal/registration/registration_result.hpp"
#include "rigcal/registration/solver_params.hpp"
#include "rigcal/registration/target.hpp"

namespace rigcal::registration {

struct GicpParams : SolverParams {
  double max_correspondence_distance = 1.0;  // m; upstream's calibration GICP uses 0.5
  /// Used only when the source comes without covariances (they are then estimated on a copy, which
  /// costs a kd-tree and a k-NN pass; call estimateCovariances once yourself to reuse them).
  CovarianceOptions source_covariance;
};

/// The target must be built with TargetOptions::normals_and_covariances.
RegistrationResult alignGicp(const Target& target, const PointCloud& source, const Pose& guess,
                             const GicpParams& params = {}, const Deadline& deadline = {});

}  // namespace rigcal::registration
