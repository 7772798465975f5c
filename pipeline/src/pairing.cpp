#include "rigcal/pipeline/pairing.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace rigcal::pipeline {

namespace {

bool passes(const InterpolationStats& s, double time, double distance, double angle, double speed,
            double accel) {
  return s.time_s < time && s.distance_m < distance && s.angle_deg < angle && s.speed < speed &&
         s.accel < accel;
}

std::string describe(const InterpolationStats& s, const config::Parameters& p) {
  std::ostringstream out;
  out.precision(3);
  const auto check = [&](const char* name, double v, double limit) {
    if (v >= limit) out << (out.tellp() > 0 ? ", " : "") << name << ' ' << v << " ≥ " << limit;
  };
  check("time", s.time_s, p.max_allowed_interpolated_time);
  check("distance", s.distance_m, p.max_allowed_interpolated_distance);
  check("angle", s.angle_deg, p.max_allowed_interpolated_angle);
  check("speed", s.speed, p.max_allowed_interpolated_speed);
  check("accel", s.accel, p.max_allowed_interpolated_accel);
  return "interpolation criteria: " + out.str();
}

}  // namespace

std::optional<Pairing> pairKeyframe(const std::vector<MappingFrame>& frames, std::size_t keyframe_frame,
                                    std::uint64_t scan_sequence, TimeNs scan_stamp_ns,
                                    const config::Parameters& params) {
  // L and R bracket the scan stamp; aux is the frame after R (the third point for acceleration).
  const auto after = std::upper_bound(frames.begin(), frames.end(), scan_stamp_ns,
                                      [](TimeNs t, const MappingFrame& f) { return t < f.stamp_ns; });
  if (after == frames.begin()) return std::nullopt;
  if (after == frames.end() || std::next(after) == frames.end()) return std::nullopt;  // not yet
  const MappingFrame& L = *std::prev(after);
  const MappingFrame& R = *after;
  const MappingFrame& aux = *std::next(after);
  const MappingFrame& kf = frames[keyframe_frame];

  Pairing p;
  p.keyframe_frame = keyframe_frame;
  p.scan_sequence = scan_sequence;
  p.scan_stamp_ns = scan_stamp_ns;
  p.stopped = kf.kind == FrameKind::kStoppedKeyframe;
  p.T_map_mapping_at_scan = interpolateAt(L.stamp_ns, L.T_map_lidar, R.stamp_ns, R.T_map_lidar, scan_stamp_ns);

  const double dt1 = toSeconds(R.stamp_ns - L.stamp_ns);
  const double dt2 = toSeconds(aux.stamp_ns - R.stamp_ns);
  InterpolationStats& s = p.stats;
  s.time_s = std::abs(toSeconds(scan_stamp_ns - kf.stamp_ns));
  s.distance_m = dt1 > 0 ? (R.path_length - L.path_length) * s.time_s / dt1 : 0.0;
  s.angle_deg = rad2deg(rotationAngleBetween(kf.T_map_lidar, p.T_map_mapping_at_scan));
  if (dt1 > 0 && dt2 > 0) {
    s.speed = std::abs(aux.path_length - L.path_length) / (dt1 + dt2);
    // Second difference of the path length; upstream drops the factor 2 in one branch.
    s.accel = 2.0 * std::abs((aux.path_length - R.path_length) / dt2 - (R.path_length - L.path_length) / dt1) /
              (dt1 + dt2);
  }

  p.standard_ok = passes(s, params.max_allowed_interpolated_time, params.max_allowed_interpolated_distance,
                         params.max_allowed_interpolated_angle, params.max_allowed_interpolated_speed,
                         params.max_allowed_interpolated_accel);
  p.straight_ok = passes(s, params.max_allowed_interpolated_time,
                         params.max_allowed_interpolated_distance_straight,
                         params.max_allowed_interpolated_angle_straight,
                         params.max_allowed_interpolated_speed_straight,
                         params.max_allowed_interpolated_accel_straight);
  if (params.calibration_use_only_stopped && !p.stopped)
    p.rejection = "not a stopped keyframe (calibration_use_only_stopped)";
  else if (!p.standard_ok && !p.straight_ok)
    p.rejection = describe(s, params);
  p.accepted = p.rejection.empty();
  return p;
}

}  // namespace rigcal::pipeline
