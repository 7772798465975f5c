#include "rigcal/sim/trajectory.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace rigcal::sim {

const char* kindName(TrajectorySegment::Kind k) {
  switch (k) {
    case TrajectorySegment::Kind::kAccelerate: return "accelerate";
    case TrajectorySegment::Kind::kCruise: return "cruise";
    case TrajectorySegment::Kind::kStop: return "stop";
    case TrajectorySegment::Kind::kTurn: return "turn";
    case TrajectorySegment::Kind::kJerk: return "jerk";
  }
  return "?";
}

namespace {

// Smoothstep S(u) = 3u² − 2u³ and its integral u³ − u⁴/2: speed blends with continuous acceleration.
double smoothstep(double u) { return u * u * (3 - 2 * u); }
double smoothstepIntegral(double u) { return u * u * u * (1 - 0.5 * u); }
// Heading fraction along a turn: the integral of a raised-cosine curvature, H(x) = x − sin(2πx)/2π.
double turnFraction(double x) { return x - std::sin(2 * M_PI * x) / (2 * M_PI); }

}  // namespace

Trajectory::Trajectory(TrajectorySpec spec, Ground ground) : spec_(std::move(spec)), ground_(std::move(ground)) {
  if (spec_.segments.empty()) throw std::invalid_argument("trajectory: no segments");
  double t = 0, v = spec_.start_speed_mps, s = 0, h = spec_.start_yaw_rad;
  for (std::size_t i = 0; i < spec_.segments.size(); ++i) {
    const TrajectorySegment& seg = spec_.segments[i];
    const std::string where = "trajectory segment " + std::to_string(i + 1) + " (" + kindName(seg.kind) + ")";
    if (!(seg.duration_s > 0)) throw std::invalid_argument(where + ": duration must be positive");
    const double v1 = seg.to_speed_mps.value_or(v);
    // Negative speed drives backwards. The gear changes at rest: a segment never crosses zero speed,
    // so its arc length is monotonic and the turn's heading profile stays a function of the path.
    if (v * v1 < 0) throw std::invalid_argument(where + ": reverses without stopping (decelerate to 0 first)");
    if (seg.kind == TrajectorySegment::Kind::kStop && (v != 0 || v1 != 0))
      throw std::invalid_argument(where + ": the vehicle must be at rest (decelerate to 0 first)");
    // Signed: negative while reversing. ∫ smoothstep blend = the mean speed.
    const double length = 0.5 * (v + v1) * seg.duration_s;
    if (seg.turn_rad != 0 && length == 0) throw std::invalid_argument(where + ": cannot turn while at rest");
    segments_.push_back({t, seg.duration_s, v, v1, s, length, h, seg.turn_rad});
    t += seg.duration_s;
    s += length;
    travelled_m_ += std::abs(length);
    if (length < 0) reversed_m_ -= length;
    v = v1;
    h += seg.turn_rad;
  }
  duration_ns_ = fromSeconds(t);

  // Integrate the planar path with Simpson's rule between table points; queries interpolate it with
  // cubic Hermite splines that use the exact velocity at both ends (C1 in time).
  const std::size_t n = std::size_t(std::ceil(t / table_step_s_)) + 1;
  table_.resize(n);
  table_[0] = spec_.start_xy;
  for (std::size_t k = 1; k < n; ++k) {
    const double a = double(k - 1) * table_step_s_, b = double(k) * table_step_s_;
    table_[k] = table_[k - 1] + (b - a) / 6.0 * (velocity(a) + 4.0 * velocity(0.5 * (a + b)) + velocity(b));
  }
}

std::size_t Trajectory::segmentAt(double t_s) const {
  const auto it = std::upper_bound(segments_.begin(), segments_.end(), t_s,
                                   [](double t, const Span& sp) { return t < sp.t0; });
  return it == segments_.begin() ? 0 : std::size_t(it - segments_.begin()) - 1;
}

Trajectory::State Trajectory::state(double t_s) const {
  const Span& sp = segments_[segmentAt(t_s)];
  const double tau = std::clamp(t_s - sp.t0, 0.0, sp.duration);
  const double u = tau / sp.duration, dv = sp.v1 - sp.v0;
  State st;
  st.v = sp.v0 + dv * smoothstep(u);
  st.a = dv / sp.duration * 6 * u * (1 - u);
  const double local = sp.v0 * tau + dv * sp.duration * smoothstepIntegral(u);
  st.s = sp.s0 + local;
  // Backwards, local and length are both negative: the fraction still runs 0 → 1, and the curvature
  // dh/ds takes the sign a steering wheel gives it (reversing with the wheel left turns the nose right).
  st.h = sp.h0 + (sp.length != 0 ? sp.turn * turnFraction(local / sp.length) : 0.0);
  // dh/ds = turn·H'(x)/length, H'(x) = 1 − cos(2πx).
  st.k = sp.length != 0 ? sp.turn * (1 - std::cos(2 * M_PI * local / sp.length)) / sp.length : 0.0;
  return st;
}

Eigen::Vector2d Trajectory::velocity(double t_s) const {
  const State st = state(t_s);
  // Side slip: the velocity turns off the body's axis toward the outside of the turn, by an angle
  // proportional to the lateral acceleration v²·κ. The lateral velocity v·β is −slip·|v|·v²κ/g in either
  // direction of travel (β's sign follows v so that backwards, too, the body slides outward).
  const double beta = -spec_.side_slip_rad_per_g * st.v * std::abs(st.v) * st.k / 9.81;
  return st.v * Eigen::Vector2d(std::cos(st.h + beta), std::sin(st.h + beta));
}

double Trajectory::speed(double t_s) const { return state(t_s).v; }
double Trajectory::acceleration(double t_s) const { return state(t_s).a; }
double Trajectory::heading(double t_s) const { return state(std::clamp(t_s, 0.0, toSeconds(duration_ns_))).h; }

Eigen::Vector2d Trajectory::position(double t_s) const {
  const double end = toSeconds(duration_ns_);
  t_s = std::clamp(t_s, 0.0, end);
  const double x = t_s / table_step_s_;
  std::size_t k = std::min(std::size_t(x), table_.size() - 2);
  const double t0 = double(k) * table_step_s_;
  const double h = table_step_s_, u = (t_s - t0) / h;
  const double u2 = u * u, u3 = u2 * u;
  const Eigen::Vector2d v0 = velocity(t0), v1 = velocity(std::min(t0 + h, end));
  return (2 * u3 - 3 * u2 + 1) * table_[k] + (u3 - 2 * u2 + u) * h * v0 + (-2 * u3 + 3 * u2) * table_[k + 1] +
         (u3 - u2) * h * v1;
}

Pose Trajectory::pose(TimeNs t) const {
  const double t_s = toSeconds(std::clamp<TimeNs>(t, 0, duration_ns_));
  const Eigen::Vector2d p = position(t_s);
  const double h = heading(t_s);
  const Eigen::Vector2d f(std::cos(h), std::sin(h)), l(-std::sin(h), std::cos(h));
  // The body rests on its four wheels: height, pitch and roll from the terrain under them.
  const Eigen::Vector2d centre = spec_.base_link_on_rear_axle ? Eigen::Vector2d(p + 0.5 * spec_.wheelbase_m * f) : p;
  const Eigen::Vector2d front = centre + 0.5 * spec_.wheelbase_m * f, rear = centre - 0.5 * spec_.wheelbase_m * f;
  const Eigen::Vector2d left = centre + 0.5 * spec_.track_m * l, right = centre - 0.5 * spec_.track_m * l;
  const double gf = ground_.height(front.x(), front.y()), gr = ground_.height(rear.x(), rear.y());
  const double gl = ground_.height(left.x(), left.y()), gri = ground_.height(right.x(), right.y());
  XyzRpy v;
  v.x = p.x();
  v.y = p.y();
  // The body's height at base_link: the wheels' mean height, or the rear axle's on the rear axle.
  v.z = spec_.base_link_on_rear_axle ? gr : 0.25 * (gf + gr + gl + gri);
  v.pitch = -std::atan2(gf - gr, spec_.wheelbase_m);  // ROS: positive pitch = nose down
  v.roll = std::atan2(gl - gri, spec_.track_m);       // positive roll = left side up
  v.yaw = h;
  const Excitation& e = spec_.excitation;
  if (e.active()) {
    v.roll += e.roll_amplitude_rad * std::sin(2 * M_PI * t_s / e.roll_period_s);
    v.pitch += e.pitch_amplitude_rad * std::sin(2 * M_PI * t_s / e.pitch_period_s + 0.7);
    v.z += e.heave_amplitude_m * std::sin(2 * M_PI * t_s / e.heave_period_s + 1.9);
  }
  return fromXyzRpy(v);
}

std::vector<Eigen::Vector2d> Trajectory::path(double spacing) const {
  std::vector<Eigen::Vector2d> out{position(0)};
  const double end = toSeconds(duration_ns_);
  for (double t = 0; t <= end; t += 0.05)
    if ((position(t) - out.back()).norm() >= spacing) out.push_back(position(t));
  out.push_back(position(end));
  return out;
}

}  // namespace rigcal::sim
