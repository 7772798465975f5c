#include "rigcal/calib/lidar_lidar/frame_pose_information.hpp"

#include "plane_correspondences.hpp"

namespace rigcal::calib {

PoseInformation framePoseInformation(const registration::Target& target, const registration::PointCloud& source,
                                     const Pose& T_target_source, double max_distance, std::size_t stride) {
  PoseInformation H = PoseInformation::Zero();
  const Eigen::Matrix3d R = T_target_source.linear();
  detail::forEachPlaneCorrespondence(target, source, T_target_source, max_distance, stride,
                                     [&](const Eigen::Vector3d& p, const Eigen::Vector3d&, const Eigen::Vector3d& n) {
                                       // n · (T exp(δ) p) changes by (Rᵀn) · (δt + δr × p) = m · δt + (p × m) · δr.
                                       const Eigen::Vector3d m = R.transpose() * n;
                                       Eigen::Matrix<double, 6, 1> J;
                                       J << m, p.cross(m);
                                       H.selfadjointView<Eigen::Upper>().rankUpdate(J);
                                     });
  return H.selfadjointView<Eigen::Upper>();
}

}  // namespace rigcal::calib
