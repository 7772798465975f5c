#pragma once
// Normal Distributions Transform (Biber & Straßer 2003, Magnusson 2009): maximises
// Σ_points Σ_nearby voxels d1·exp(−d2/2 · xᵀΣ⁻¹x) with PCL's d1, d2 from outlier_ratio and resolution.
// Solved by Newton steps on the score (PCL's Hessian without the transform's second-derivative terms),
// Levenberg–Marquardt damped, each update capped at step_size and accepted only when the score improves
// (instead of PCL's Moré–Thuente line search).
#include "rigcal/core/pose.hpp"
#include "rigcal/registration/deadline.hpp"
#include "rigcal/registration/ndt_grid.hpp"
#include "rigcal/registration/point_cloud.hpp"
#include "rigcal/registration/registration_result.hpp"
#include "rigcal/registration/solver_params.hpp"
#include "rigcal/registration/target.hpp"

namespace rigcal::registration {

struct NdtParams : SolverParams {
  double resolution = 1.0;     // m; the target needs a grid of this resolution (TargetOptions::ndt_resolutions)
  double step_size = 0.1;      // largest update per iteration, norm of (metres, radians) as PCL
  double outlier_ratio = 0.55;
  NdtNeighborhood neighborhood = NdtNeighborhood::kDirect7;
  /// Only for the result's rmse / inlier_ratio / fitness (NDT itself matches voxels, not points).
  double max_correspondence_distance = 1.0;
  // Note: upstream passes epsilon 0.1 to PCL, where it bounds the *squared* translation of the last step
  // (m²) and so often stops a decimetre short; transformation_epsilon here is the step's translation in m.
};

RegistrationResult alignNdt(const Target& target, const PointCloud& source, const Pose& guess,
                            const NdtParams& params = {}, const Deadline& deadline = {});

}  // namespace rigcal::registration
