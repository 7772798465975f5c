#include "rigcal/registration/point_to_plane_information.hpp"

#include <Eigen/Eigenvalues>

#include <algorithm>

namespace rigcal::registration {
namespace {
double smallestEigenvalue(const Eigen::Matrix3d& H) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(H, Eigen::EigenvaluesOnly);
  return std::max(0.0, es.eigenvalues()(0));
}
}  // namespace

void PointToPlaneInformation::add(const Eigen::Vector3d& arm, const Eigen::Vector3d& normal) {
  const Eigen::Vector3d jr = arm.cross(normal);
  translation += normal * normal.transpose();
  rotation += jr * jr.transpose();
  lever_sq += arm.squaredNorm();
  ++correspondences;
}

PointToPlaneInformation& PointToPlaneInformation::operator+=(const PointToPlaneInformation& other) {
  translation += other.translation;
  rotation += other.rotation;
  lever_sq += other.lever_sq;
  correspondences += other.correspondences;
  return *this;
}

double PointToPlaneInformation::weakestTranslationShare() const {
  return correspondences > 0 ? smallestEigenvalue(translation) / double(correspondences) : 0.0;
}

double PointToPlaneInformation::weakestRotationShare() const {
  return lever_sq > 0 ? smallestEigenvalue(rotation) / lever_sq : 0.0;
}

double PointToPlaneInformation::weakestRelative() const {
  const double t = translation.trace(), r = rotation.trace();
  if (t <= 0 || r <= 0) return 0.0;
  return std::min(3 * smallestEigenvalue(translation) / t, 3 * smallestEigenvalue(rotation) / r);
}

}  // namespace rigcal::registration
