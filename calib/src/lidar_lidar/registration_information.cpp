#include "rigcal/calib/lidar_lidar/registration_information.hpp"

#include <Eigen/Eigenvalues>

#include "plane_correspondences.hpp"
#include "rigcal/registration/point_to_plane_information.hpp"

namespace rigcal::calib {
namespace {

std::array<DirectionInformation, 3> decompose(const Eigen::Matrix3d& H, double normaliser, double weak_share,
                                              const std::array<const char*, 3>& names) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(H);
  std::array<DirectionInformation, 3> out;
  for (int k = 0; k < 3; ++k) {
    auto& d = out[std::size_t(k)];
    d.direction = es.eigenvectors().col(k).normalized();
    Eigen::Index axis = 0;
    d.direction.cwiseAbs().maxCoeff(&axis);
    if (d.direction[axis] < 0) d.direction = -d.direction;
    d.name = names[std::size_t(axis)];
    d.eigenvalue = std::max(0.0, es.eigenvalues()[k]);
    d.share = normaliser > 0 ? d.eigenvalue / normaliser : 0.0;
    d.weak = d.share < weak_share;
  }
  return out;
}

}  // namespace

std::vector<std::string> RegistrationInformation::weakDirections() const {
  std::vector<std::string> names;
  for (const auto* block : {&translation, &rotation})
    for (const auto& d : *block)
      if (d.weak) names.push_back(d.name);
  return names;
}

RegistrationInformation registrationInformation(const registration::Target& target,
                                                const registration::PointCloud& source, const Pose& T,
                                                double max_distance, double weak_share) {
  RegistrationInformation info;
  registration::PointToPlaneInformation H;
  const Eigen::Vector3d t = T.translation();
  detail::forEachPlaneCorrespondence(target, source, T, max_distance, 1,
                                     [&](const Eigen::Vector3d&, const Eigen::Vector3d& q, const Eigen::Vector3d& n) {
                                       H.add(q - t, n);
                                     });
  info.correspondences = H.correspondences;
  info.translation = decompose(H.translation, double(H.correspondences), weak_share, {"x", "y", "z"});
  info.rotation = decompose(H.rotation, H.lever_sq, weak_share, {"roll", "pitch", "yaw"});
  return info;
}

}  // namespace rigcal::calib
