#pragma once
// A time-sorted sequence of stamped poses T_world_pose with geodesic interpolation on SE(3) between the
// two bracketing poses, a·exp(τ·log(a⁻¹·b)) as lidar_align does. Never extrapolates: a time outside
// [begin, end] gives std::nullopt.
#include <cstddef>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "rigcal/core/pose.hpp"
#include "rigcal/core/time.hpp"

namespace rigcal::calib {

struct PoseCsv;

class PoseTrajectory {
 public:
  /// Needs ≥ 2 poses with strictly increasing stamps; throws std::invalid_argument otherwise.
  PoseTrajectory(std::vector<TimeNs> stamps, std::vector<Pose> poses);
  explicit PoseTrajectory(const PoseCsv& csv);

  [[nodiscard]] std::size_t size() const { return stamps_.size(); }
  [[nodiscard]] TimeNs begin() const { return stamps_.front(); }
  [[nodiscard]] TimeNs end() const { return stamps_.back(); }
  [[nodiscard]] TimeNs stamp(std::size_t i) const { return stamps_[i]; }
  [[nodiscard]] const Pose& pose(std::size_t i) const { return poses_[i]; }
  [[nodiscard]] bool covers(TimeNs t) const { return t >= begin() && t <= end(); }

  /// T_world_pose at `t`, or nullopt outside [begin, end].
  [[nodiscard]] std::optional<Pose> at(TimeNs t) const { return at(t, 0.0); }
  /// T_world_pose at t + offset_s, the offset kept at sub-nanosecond resolution (the optimiser moves it
  /// continuously). `hint` (in/out) is the segment of the previous query: consecutive queries at
  /// nearby times then cost O(1) instead of a binary search.
  [[nodiscard]] std::optional<Pose> at(TimeNs t, double offset_s, std::size_t* hint = nullptr) const;

 private:
  // Segment i joins pose a = pose i and b = pose i+1 along a·exp(τ·ξ), ξ = log(a⁻¹·b) = (rho, angle·axis).
  // With K the skew matrix of the axis, φ = τ·angle and the closed-form SE(3) exponential,
  //   R(τ) = a.R + sin φ·(a.R·K) + (1 − cos φ)·(a.R·K²)
  //   t(τ) = a.t + τ·(a.R·rho + j1(φ)·a.R·K·rho + j2(φ)·a.R·K²·rho),
  // so the products with a.R are precomputed once per segment and a query costs 27 multiply-adds
  // (plus sin/cos when φ is not tiny) instead of three 3×3 matrix products.
  struct Segment {
    Eigen::Matrix3d RK, RK2;   // a.R·K, a.R·K²
    Eigen::Vector3d u0, u1, u2;  // a.R·rho, a.R·K·rho, a.R·K²·rho
    double angle = 0.0;
  };
  [[nodiscard]] std::optional<std::size_t> locate(double rel_ns, std::size_t* hint) const;

  std::vector<TimeNs> stamps_;
  std::vector<double> rel_ns_;  // stamps_ − stamps_[0], as double
  std::vector<Pose> poses_;
  std::vector<Segment> segments_;
};

}  // namespace rigcal::calib
