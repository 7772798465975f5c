#pragma once
// The vehicle's motion: a sequence of timed segments (accelerate, cruise, stop, turn, jerk) defines a
// speed profile and a heading profile; the path follows by integration, and the body rests on the
// ground under its wheels (height, pitch and roll from the terrain), optionally rocked by a
// roll/pitch/heave excitation for lidar–pose calibration.
//
// Smoothness: speed changes follow a smoothstep (acceleration continuous, zero at segment ends) and a
// turn spreads its heading change with a raised-cosine curvature, so position is C2 and heading C1 in
// time. base_link sits on the ground midway between the axles (or on the rear axle, base_link_on_rear_axle),
// x forward, z up. Negative speed drives backwards (direction changes only at rest); the turn of a
// segment is its heading change either way. base_link's origin moves along its x axis (no side slip: the kinematic rear axle)
// unless side_slip_rad_per_g turns its velocity off the axis, toward the outside of a turn.
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "rigcal/core/pose.hpp"
#include "rigcal/core/time.hpp"
#include "rigcal/sim/ground.hpp"

namespace rigcal::sim {

struct TrajectorySegment {
  enum class Kind : std::uint8_t { kAccelerate, kCruise, kStop, kTurn, kJerk };
  Kind kind = Kind::kCruise;
  double duration_s = 1.0;
  std::optional<double> to_speed_mps;  // speed reached at the segment's end (negative: reversing); absent: unchanged
  double turn_rad = 0.0;               // heading change over the segment (positive: to the left)
};

const char* kindName(TrajectorySegment::Kind k);

struct Excitation {
  double roll_amplitude_rad = 0, pitch_amplitude_rad = 0, heave_amplitude_m = 0;
  double roll_period_s = 2.3, pitch_period_s = 3.1, heave_period_s = 1.7;
  [[nodiscard]] bool active() const {
    return roll_amplitude_rad != 0 || pitch_amplitude_rad != 0 || heave_amplitude_m != 0;
  }
};

struct TrajectorySpec {
  Eigen::Vector2d start_xy{0, 0};
  double start_yaw_rad = 0;
  double start_speed_mps = 0;
  std::vector<TrajectorySegment> segments;
  Excitation excitation;
  double wheelbase_m = 2.7;
  double track_m = 1.6;
  bool base_link_on_rear_axle = false;  // the wheels' ground contact: rear axle at base_link (Autoware)
  double side_slip_rad_per_g = 0.0;     // slip angle of base_link's velocity per g of lateral acceleration
};

class Trajectory {
 public:
  /// Validates the spec (throws std::invalid_argument naming the segment) and integrates the path.
  Trajectory(TrajectorySpec spec, Ground ground);

  [[nodiscard]] TimeNs duration() const { return duration_ns_; }
  /// T_world_base at `t` ns after the start (clamped to [0, duration]).
  [[nodiscard]] Pose pose(TimeNs t) const;
  /// Along-track speed (m/s), acceleration (m/s²) and heading (rad) at t seconds.
  [[nodiscard]] double speed(double t_s) const;
  [[nodiscard]] double acceleration(double t_s) const;
  [[nodiscard]] double heading(double t_s) const;
  [[nodiscard]] Eigen::Vector2d position(double t_s) const;
  /// Path points every `spacing` metres of travel (and the end), for keeping the road clear.
  [[nodiscard]] std::vector<Eigen::Vector2d> path(double spacing) const;
  /// Distance driven, forwards and backwards.
  [[nodiscard]] double length() const { return travelled_m_; }
  /// Of which driven backwards (negative speed).
  [[nodiscard]] double reversedLength() const { return reversed_m_; }
  [[nodiscard]] const TrajectorySpec& spec() const { return spec_; }
  /// Index of the segment active at t seconds.
  [[nodiscard]] std::size_t segmentAt(double t_s) const;
  [[nodiscard]] double segmentStart(std::size_t i) const { return segments_.at(i).t0; }

 private:
  struct Span {
    double t0, duration, v0, v1, s0, length, h0, turn;  // s0, length: signed arc length
  };
  struct State {
    double s, v, a, h, k;  // signed arc length, speed, acceleration, heading, path curvature dh/ds (1/m)
  };
  [[nodiscard]] State state(double t_s) const;
  [[nodiscard]] Eigen::Vector2d velocity(double t_s) const;

  TrajectorySpec spec_;
  Ground ground_;
  std::vector<Span> segments_;
  TimeNs duration_ns_ = 0;
  double travelled_m_ = 0, reversed_m_ = 0;
  double table_step_s_ = 1e-3;
  std::vector<Eigen::Vector2d> table_;  // integrated positions every table_step_s_
};

}  // namespace rigcal::sim
