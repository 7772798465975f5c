#include "rigcal/calib/lidar_lidar/frame_pose_information.hpp"

#include <algorithm>

namespace rigcal::calib {

PoseInformation framePoseInformation(const registration::Target& target, const registration::PointCloud& source,
                                     const Pose& T_target_source, double max_distance, std::size_t stride) {
  PoseInformation H = PoseInformation::Zero();
  const Eigen::Matrix3d R = T_target_source.linear();
  const auto& normals = target.cloud().normals;
  if (normals.empty()) return H;
  for (std::size_t i = 0; i < source.points.size(); i += std::max<std::size_t>(1, stride)) {
    const Eigen::Vector3d p = source.points[i].head<3>();
    const Eigen::Vector4d q = (T_target_source * p).homogeneous();
    registration::Neighbor nb;
    if (!target.tree().nearest(q, max_distance * max_distance, &nb)) continue;
    const Eigen::Vector3d n = normals[nb.index].head<3>();
    if (n.squaredNorm() < 0.5) continue;  // no normal estimated there
    // n · (T exp(δ) p) changes by (Rᵀn) · (δt + δr × p) = m · δt + (p × m) · δr.
    const Eigen::Vector3d m = R.transpose() * n;
    Eigen::Matrix<double, 6, 1> J;
    J << m, p.cross(m);
    H.selfadjointView<Eigen::Upper>().rankUpdate(J);
  }
  return H.selfadjointView<Eigen::Upper>();
}

}  // namespace rigcal::calib
