#pragma once
// The point-to-plane Gauss-Newton information of a pose: H = Σ JᵀJ with J = [n, arm × n] for a translation
// and a rotation about a centre (arm = point − centre). Kept as its translation and rotation blocks (their
// units differ) with what normalises each: the correspondence count and Σ|arm|². Both calib's
// registrationInformation (a registered pair) and the pipeline's frame ranking (one cloud against its own
// planes) accumulate it, so they agree on what "constrained" means.
#include <cstddef>

#include <Eigen/Core>

namespace rigcal::registration {

struct PointToPlaneInformation {
  Eigen::Matrix3d translation = Eigen::Matrix3d::Zero();  // Σ n nᵀ
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Zero();     // Σ (arm × n)(arm × n)ᵀ
  double lever_sq = 0.0;                                  // Σ |arm|²
  std::size_t correspondences = 0;

  /// One correspondence: `normal` unit, `arm` from the rotation centre to the point.
  void add(const Eigen::Vector3d& arm, const Eigen::Vector3d& normal);
  PointToPlaneInformation& operator+=(const PointToPlaneInformation& other);

  /// The smallest eigenvalue of the translation block over the count: the share of normals along the
  /// least constrained translation (the three shares add up to 1, so at most 1/3).
  [[nodiscard]] double weakestTranslationShare() const;
  /// The same for rotation, over Σ|arm|².
  [[nodiscard]] double weakestRotationShare() const;
  /// How evenly the worst block is constrained: min over the two blocks of smallest eigenvalue / mean
  /// eigenvalue, in [0, 1] (1: isotropic; 0: a free direction). Per block because rotation about a lidar is
  /// always less constrained than translation (normals point along the lever arms), which a common scale
  /// would make the only thing that counts.
  [[nodiscard]] double weakestRelative() const;
};

}  // namespace rigcal::registration
