#pragma once
// Rigid transforms. A pose is named T_to_from: it maps points expressed in `from` into `to`,
// e.g. T_map_lidar * p_lidar = p_map, and T_a_c = T_a_b * T_b_c.
#include <Eigen/Geometry>

#include "rigcal/core/time.hpp"

namespace rigcal {

using Pose = Eigen::Isometry3d;
using Vector6d = Eigen::Matrix<double, 6, 1>;

/// x, y, z in metres and roll, pitch, yaw in radians with R = Rz(yaw)·Ry(pitch)·Rx(roll) (the ROS/URDF
/// convention used by Autoware sensor kits).
struct XyzRpy {
  double x = 0, y = 0, z = 0, roll = 0, pitch = 0, yaw = 0;
};

Pose fromXyzRpy(const XyzRpy& v);
/// Inverse of fromXyzRpy; pitch is in [−π/2, π/2].
XyzRpy toXyzRpy(const Pose& T);

Eigen::Matrix3d skew(const Eigen::Vector3d& v);
/// SO(3) exponential / logarithm (rotation vector, radians). Stable near zero and near π.
Eigen::Matrix3d expSO3(const Eigen::Vector3d& w);
Eigen::Vector3d logSO3(const Eigen::Matrix3d& R);

/// SE(3) exponential / logarithm with the tangent ordered (ρ translation part, ω rotation vector).
Pose expSE3(const Vector6d& xi);
Vector6d logSE3(const Pose& T);

/// Translation lerp + rotation slerp, t in [0, 1] (t outside extrapolates the translation).
Pose interpolateLerpSlerp(const Pose& a, const Pose& b, double t);
/// Geodesic on SE(3): a·exp(t·log(a⁻¹·b)) (screw motion, as lidar_align does).
Pose interpolateGeodesic(const Pose& a, const Pose& b, double t);
/// Lerp/slerp between two stamped poses, evaluated at time t (t_a != t_b).
Pose interpolateAt(TimeNs t_a, const Pose& a, TimeNs t_b, const Pose& b, TimeNs t);

/// Rotation angle of T (radians, in [0, π]).
double rotationAngle(const Pose& T);
/// Rotation angle between two poses' orientations (radians).
double rotationAngleBetween(const Pose& a, const Pose& b);

constexpr double deg2rad(double d) { return d * 0.017453292519943295; }
constexpr double rad2deg(double r) { return r * 57.29577951308232; }

}  // namespace rigcal
