#pragma once
// How well a registered cloud pair constrains each direction of the pose: the point-to-plane Gauss-Newton
// Hessian H = Σ JᵀJ over the correspondences, J = [n, (q − t) × n] for a translation of the source and a
// rotation about the source origin t, in the target frame. Its translation and rotation blocks are
// eigen-decomposed separately (units differ); each eigenvalue is given as a share:
//   translation: λ / correspondences (the three add up to 1: the share of the normals along it);
//   rotation:    λ / Σ|q − t|² (the same for the lever arms).
// A direction whose share is under `weak_share` is poorly constrained (a corridor along its axis, a bay
// with one wall): its value then comes from the start, not from the data.
#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "rigcal/core/pose.hpp"
#include "rigcal/registration/point_cloud.hpp"
#include "rigcal/registration/target.hpp"

namespace rigcal::calib {

/// Measured on a real HDL-32E street scan: its weakest directions hold 0.04-0.08 of the information; the same
/// scan's ground alone 0.011-0.026 along x / y and 0.002 about yaw.
inline constexpr double kWeakShare = 0.03;

struct DirectionInformation {
  std::string name;             // the nearest axis: x, y, z (translation) or roll, pitch, yaw (rotation)
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();  // unit, target frame
  double eigenvalue = 0.0;      // of the Hessian block (m⁻² free for translation, per rad² for rotation)
  double share = 0.0;           // normalised as above, in [0, 1]
  bool weak = false;
};

struct RegistrationInformation {
  std::size_t correspondences = 0;
  std::array<DirectionInformation, 3> translation;  // ascending eigenvalue
  std::array<DirectionInformation, 3> rotation;
  /// "x", "yaw", ... of the weak directions (empty when all six are constrained).
  [[nodiscard]] std::vector<std::string> weakDirections() const;
};

/// `target` must have normals. Correspondences: nearest target point within max_distance.
RegistrationInformation registrationInformation(const registration::Target& target,
                                                const registration::PointCloud& source, const Pose& T_target_source,
                                                double max_distance, double weak_share = kWeakShare);

}  // namespace rigcal::calib
