#include "rigcal/calib/pose_trajectory.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "rigcal/calib/pose_csv.hpp"

namespace rigcal::calib {
namespace {

// a·exp(τ·ξ) with ξ = (rho, angle·axis): closed-form SE(3) exponential. With φ = τ·angle and K the
// skew matrix of the axis: R = I + sin φ K + (1 − cos φ) K², t = (I + (1 − cos φ)/φ K + (1 − sin φ/φ) K²)·τρ.
Pose geodesicStep(const Pose& a, const Eigen::Vector3d& rho, const Eigen::Vector3d& axis, double angle,
                  double tau) {
  const double phi = tau * angle;
  double s, c1, j1, j2;  // sin φ, 1 − cos φ, and the two translation coefficients
  if (std::abs(phi) < 1e-4) {  // series: avoids 0/0, exact to double precision at this size
    const double p2 = phi * phi;
    s = phi * (1.0 - p2 / 6.0);
    c1 = 0.5 * p2 * (1.0 - p2 / 12.0);
    j1 = 0.5 * phi * (1.0 - p2 / 12.0);
    j2 = p2 / 6.0 * (1.0 - p2 / 20.0);
  } else {
    s = std::sin(phi);
    c1 = 1.0 - std::cos(phi);
    j1 = c1 / phi;
    j2 = 1.0 - s / phi;
  }
  const Eigen::Matrix3d K = skew(axis);
  const Eigen::Matrix3d K2 = K * K;
  const Eigen::Matrix3d R = Eigen::Matrix3d::Identity() + s * K + c1 * K2;
  const Eigen::Vector3d v = tau * rho;
  const Eigen::Vector3d t = v + j1 * (K * v) + j2 * (K2 * v);
  Pose out;
  out.linear() = a.linear() * R;
  out.translation() = a.linear() * t + a.translation();
  out.makeAffine();
  return out;
}

}  // namespace

PoseTrajectory::PoseTrajectory(std::vector<TimeNs> stamps, std::vector<Pose> poses)
    : stamps_(std::move(stamps)), poses_(std::move(poses)) {
  if (stamps_.size() != poses_.size())
    throw std::invalid_argument("PoseTrajectory: " + std::to_string(stamps_.size()) + " stamps but " +
                                std::to_string(poses_.size()) + " poses");
  if (stamps_.size() < 2)
    throw std::invalid_argument("PoseTrajectory: needs at least 2 poses, got " +
                                std::to_string(stamps_.size()));
  rel_ns_.reserve(stamps_.size());
  segments_.reserve(stamps_.size() - 1);
  for (std::size_t i = 0; i < stamps_.size(); ++i) {
    if (i > 0 && stamps_[i] <= stamps_[i - 1])
      throw std::invalid_argument("PoseTrajectory: stamp " + std::to_string(i) + " (" +
                                  std::to_string(stamps_[i]) + " ns) is not after the previous one");
    rel_ns_.push_back(static_cast<double>(stamps_[i] - stamps_[0]));
    if (i == 0) continue;
    const Vector6d xi = logSE3(poses_[i - 1].inverse() * poses_[i]);
    Segment seg;
    seg.rho = xi.head<3>();
    seg.angle = xi.tail<3>().norm();
    seg.axis = seg.angle > 0.0 ? Eigen::Vector3d(xi.tail<3>() / seg.angle) : Eigen::Vector3d::UnitX();
    segments_.push_back(seg);
  }
}

PoseTrajectory::PoseTrajectory(const PoseCsv& csv) : PoseTrajectory(csv.stamps, csv.poses) {}

std::optional<std::size_t> PoseTrajectory::locate(double rel_ns, std::size_t* hint) const {
  if (!(rel_ns >= 0.0 && rel_ns <= rel_ns_.back())) return std::nullopt;  // also rejects NaN
  const std::size_t last = segments_.size() - 1;
  if (hint && *hint <= last) {
    // Queries come in time order: the hinted segment or its successor almost always holds the time.
    for (std::size_t i = *hint, n = 0; i <= last && n < 3; ++i, ++n)
      if (rel_ns >= rel_ns_[i] && rel_ns <= rel_ns_[i + 1]) return *hint = i;
  }
  const auto it = std::upper_bound(rel_ns_.begin(), rel_ns_.end(), rel_ns);
  const std::size_t i = std::min(last, static_cast<std::size_t>(it - rel_ns_.begin()) - 1);
  if (hint) *hint = i;
  return i;
}

std::optional<Pose> PoseTrajectory::at(TimeNs t, double offset_s, std::size_t* hint) const {
  const double rel = static_cast<double>(t - stamps_[0]) + offset_s * 1e9;
  const auto i = locate(rel, hint);
  if (!i) return std::nullopt;
  const double tau = (rel - rel_ns_[*i]) / (rel_ns_[*i + 1] - rel_ns_[*i]);
  const Segment& seg = segments_[*i];
  return geodesicStep(poses_[*i], seg.rho, seg.axis, seg.angle, tau);
}

}  // namespace rigcal::calib
