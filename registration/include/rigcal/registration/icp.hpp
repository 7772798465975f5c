#pragma once
// Iterative closest point, point-to-point or point-to-plane, solved by Gauss–Newton with
// Levenberg–Marquardt safeguarding on SE(3). Point-to-point is the robust coarse aligner; point-to-plane
// converges faster and finer on structured scenes but needs target normals.
#include "rigcal/core/pose.hpp"
#include "rigcal/registration/deadline.hpp"
#include "rigcal/registration/point_cloud.hpp"
#include "rigcal/registration/registration_result.hpp"
#include "rigcal/registration/solver_params.hpp"
#include "rigcal/registration/target.hpp"

namespace rigcal::registration {

enum class IcpMethod { kPointToPoint, kPointToPlane };

struct IcpParams : SolverParams {
  IcpMethod method = IcpMethod::kPointToPoint;
  double max_correspondence_distance = 1.0;  // m; upstream's coarse / fine / ultra-fine: 0.5 / 0.1 / 0.05
};

/// Aligns `source` to `target` starting from `guess`. Point-to-plane needs a target built with
/// TargetOptions::normals_and_covariances. Never throws for bad data: see RegistrationResult::status.
RegistrationResult alignIcp(const Target& target, const PointCloud& source, const Pose& guess,
                            const IcpParams& params = {}, const Deadline& deadline = {});

}  // namespace rigcal::registration
