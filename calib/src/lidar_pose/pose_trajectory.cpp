#include "rigcal/calib/lidar_pose/pose_trajectory.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "rigcal/calib/lidar_pose/pose_csv.hpp"

namespace rigcal::calib {
namespace {

// The coefficients of the SE(3) exponential at φ: sin φ, 1 − cos φ, (1 − cos φ)/φ, 1 − sin φ/φ.
struct ExpCoefficients {
  double s, c1, j1, j2;
};
ExpCoefficients expCoefficients(double phi) {
  if (std::abs(phi) < 1e-4) {  // series: avoids 0/0, exact to double precision at this size
    const double p2 = phi * phi;
    return {phi * (1.0 - p2 / 6.0), 0.5 * p2 * (1.0 - p2 / 12.0), 0.5 * phi * (1.0 - p2 / 12.0),
            p2 / 6.0 * (1.0 - p2 / 20.0)};
  }
  const double s = std::sin(phi), c1 = 1.0 - std::cos(phi);
  return {s, c1, c1 / phi, 1.0 - s / phi};
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
    const Eigen::Vector3d rho = xi.head<3>();
    Segment seg;
    seg.angle = xi.tail<3>().norm();
    const Eigen::Vector3d axis = seg.angle > 0.0 ? Eigen::Vector3d(xi.tail<3>() / seg.angle) : Eigen::Vector3d::UnitX();
    const Eigen::Matrix3d K = skew(axis);
    const Eigen::Matrix3d& aR = poses_[i - 1].linear();
    seg.RK = aR * K;
    seg.RK2 = seg.RK * K;
    seg.u0 = aR * rho;
    seg.u1 = seg.RK * rho;
    seg.u2 = seg.RK2 * rho;
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
  const ExpCoefficients k = expCoefficients(tau * seg.angle);
  const Pose& a = poses_[*i];
  Pose out;
  out.linear() = a.linear() + k.s * seg.RK + k.c1 * seg.RK2;
  out.translation() = a.translation() + tau * (seg.u0 + k.j1 * seg.u1 + k.j2 * seg.u2);
  out.makeAffine();
  return out;
}

}  // namespace rigcal::calib
