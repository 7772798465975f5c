#pragma once
// How much one calibration frame constrains each direction of the extrinsic at a pose: the point-to-plane
// Gauss-Newton information H = Σ JᵀJ, J = [m, p × m], for a small change T · exp([δt, δr]) of the extrinsic
// (δt, δr in the calibration lidar's own frame; p a source point, m the target normal in that frame). The
// verdict weights each frame's scatter by it (lidar_lidar_verdict.hpp): a frame that does not see along a
// direction says little about it there, and the result refined over all frames does not follow it there.
#include <cstddef>

#include <Eigen/Core>

#include "rigcal/core/pose.hpp"
#include "rigcal/registration/point_cloud.hpp"
#include "rigcal/registration/target.hpp"

namespace rigcal::calib {

using PoseInformation = Eigen::Matrix<double, 6, 6>;

/// Over every `stride`-th source point with a target neighbour (with a normal) within `max_distance` under
/// T_target_source. Zero when nothing corresponds.
PoseInformation framePoseInformation(const registration::Target& target, const registration::PointCloud& source,
                                     const Pose& T_target_source, double max_distance, std::size_t stride = 1);

}  // namespace rigcal::calib
