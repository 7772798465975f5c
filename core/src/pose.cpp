#include "rigcal/core/pose.hpp"

#include <algorithm>
#include <cmath>

namespace rigcal {

Pose fromXyzRpy(const XyzRpy& v) {
  Pose T = Pose::Identity();
  T.linear() = (Eigen::AngleAxisd(v.yaw, Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd(v.pitch, Eigen::Vector3d::UnitY()) *
                Eigen::AngleAxisd(v.roll, Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  T.translation() = Eigen::Vector3d(v.x, v.y, v.z);
  return T;
}

XyzRpy toXyzRpy(const Pose& T) {
  const Eigen::Matrix3d& R = T.linear();
  XyzRpy v;
  v.x = T.translation().x();
  v.y = T.translation().y();
  v.z = T.translation().z();
  // R = Rz(yaw)·Ry(pitch)·Rx(roll): R(2,0) = −sin(pitch).
  v.pitch = std::asin(std::clamp(-R(2, 0), -1.0, 1.0));
  if (std::abs(R(2, 0)) < 1.0 - 1e-12) {
    v.roll = std::atan2(R(2, 1), R(2, 2));
    v.yaw = std::atan2(R(1, 0), R(0, 0));
  } else {  // gimbal lock: only roll ± yaw is defined; put it all in yaw.
    v.roll = 0.0;
    v.yaw = std::atan2(-R(0, 1), R(1, 1));
  }
  return v;
}

Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d S;
  S << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return S;
}

Eigen::Matrix3d expSO3(const Eigen::Vector3d& w) {
  const double theta = w.norm();
  if (theta < 1e-10) return Eigen::Matrix3d::Identity() + skew(w);
  return Eigen::AngleAxisd(theta, w / theta).toRotationMatrix();
}

Eigen::Vector3d logSO3(const Eigen::Matrix3d& R) {
  // Eigen's AngleAxis goes through the quaternion, which is well conditioned everywhere.
  const Eigen::AngleAxisd aa(Eigen::Quaterniond(R).normalized());
  double angle = aa.angle();
  Eigen::Vector3d axis = aa.axis();
  if (angle > M_PI) {  // keep the angle in [0, π]
    angle = 2.0 * M_PI - angle;
    axis = -axis;
  }
  return axis * angle;
}

namespace {
// Left Jacobian of SO(3) ("V" in the SE(3) exponential) and its inverse.
Eigen::Matrix3d leftJacobian(const Eigen::Vector3d& w) {
  const double theta = w.norm();
  const Eigen::Matrix3d W = skew(w);
  if (theta < 1e-6) return Eigen::Matrix3d::Identity() + 0.5 * W + W * W / 6.0;
  const double t2 = theta * theta;
  return Eigen::Matrix3d::Identity() + (1.0 - std::cos(theta)) / t2 * W +
         (theta - std::sin(theta)) / (t2 * theta) * W * W;
}

Eigen::Matrix3d leftJacobianInverse(const Eigen::Vector3d& w) {
  const double theta = w.norm();
  const Eigen::Matrix3d W = skew(w);
  if (theta < 1e-6) return Eigen::Matrix3d::Identity() - 0.5 * W + W * W / 12.0;
  const double half = 0.5 * theta;
  const double cot = std::cos(half) / std::sin(half);
  return Eigen::Matrix3d::Identity() - 0.5 * W +
         (1.0 - half * cot) / (theta * theta) * W * W;
}
}  // namespace

Pose expSE3(const Vector6d& xi) {
  const Eigen::Vector3d rho = xi.head<3>();
  const Eigen::Vector3d w = xi.tail<3>();
  Pose T = Pose::Identity();
  T.linear() = expSO3(w);
  T.translation() = leftJacobian(w) * rho;
  return T;
}

Vector6d logSE3(const Pose& T) {
  const Eigen::Vector3d w = logSO3(T.linear());
  Vector6d xi;
  xi.head<3>() = leftJacobianInverse(w) * T.translation();
  xi.tail<3>() = w;
  return xi;
}

Pose interpolateLerpSlerp(const Pose& a, const Pose& b, double t) {
  const Eigen::Quaterniond qa(a.linear());
  const Eigen::Quaterniond qb(b.linear());
  Pose T = Pose::Identity();
  T.linear() = qa.slerp(std::clamp(t, 0.0, 1.0), qb).normalized().toRotationMatrix();
  T.translation() = (1.0 - t) * a.translation() + t * b.translation();
  return T;
}

Pose interpolateGeodesic(const Pose& a, const Pose& b, double t) {
  return a * expSE3(t * logSE3(a.inverse() * b));
}

Pose interpolateAt(TimeNs t_a, const Pose& a, TimeNs t_b, const Pose& b, TimeNs t) {
  const double s = static_cast<double>(t - t_a) / static_cast<double>(t_b - t_a);
  return interpolateLerpSlerp(a, b, s);
}

double rotationAngle(const Pose& T) { return logSO3(T.linear()).norm(); }

double rotationAngleBetween(const Pose& a, const Pose& b) {
  return logSO3(a.linear().transpose() * b.linear()).norm();
}

}  // namespace rigcal
