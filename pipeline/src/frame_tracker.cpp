#include "rigcal/pipeline/frame_tracker.hpp"

#include <algorithm>
#include <cmath>

namespace rigcal::pipeline {

const char* toString(FrameKind kind) {
  switch (kind) {
    case FrameKind::kDropped: return "dropped";
    case FrameKind::kFrame: return "frame";
    case FrameKind::kStopped: return "stopped";
    case FrameKind::kStoppedKeyframe: return "stopped-keyframe";
    case FrameKind::kKeyframe: return "keyframe";
  }
  return "?";
}

FrameTracker::FrameTracker(const config::Parameters& params) : params_(params) {}

bool FrameTracker::full() const { return int(frames_.size()) >= params_.mapping_max_frames; }

Pose FrameTracker::predict(TimeNs stamp_ns) const {
  if (frames_.empty()) return Pose::Identity();
  const MappingFrame& last = frames_.back();
  if (frames_.size() < 2 || last.lost || (last_processed_ && last_processed_->kind == FrameKind::kStopped))
    return last_processed_ ? last_processed_->T_map_lidar : last.T_map_lidar;
  const MappingFrame& prev = frames_[frames_.size() - 2];
  const double span = double(last.stamp_ns - prev.stamp_ns);
  if (span <= 0) return last.T_map_lidar;
  // Constant velocity: repeat the last inter-frame motion, scaled to the elapsed time.
  const Pose step = prev.T_map_lidar.inverse() * last.T_map_lidar;
  const double steps = double(stamp_ns - last.stamp_ns) / span;
  return last.T_map_lidar * expSE3(steps * logSE3(step));
}

MappingFrame FrameTracker::add(std::uint64_t sequence, TimeNs stamp_ns, const Pose& T_map_lidar,
                               bool registration_ok) {
  MappingFrame f;
  f.sequence = sequence;
  f.stamp_ns = stamp_ns;
  f.T_map_lidar = T_map_lidar;

  if (frames_.empty()) {  // the first frame defines the map and is the first keyframe
    f.kind = FrameKind::kKeyframe;
    f.keyframe_index = 0;
    frames_.push_back(f);
    keyframes_.push_back(0);
    last_processed_ = f;
    return f;
  }

  const MappingFrame& prev = frames_.back();
  const double dt = toSeconds(stamp_ns - prev.stamp_ns);
  f.delta = (prev.T_map_lidar.inverse() * T_map_lidar).translation().norm();
  f.speed = dt > 0 ? f.delta / dt : 0.0;
  f.speed_known = dt > 0;

  // Lost: registration failure, unseen for too long, or an implausible change of speed.
  const double dt_processed = toSeconds(stamp_ns - last_processed_->stamp_ns);
  if (!registration_ok) {
    f.lost = true;
    f.lost_reason = "registration failed";
  } else if (dt_processed >= params_.mapping_lost_timeout) {
    f.lost = true;
    f.lost_reason = "no frame for " + std::to_string(dt_processed) + " s";
  } else if (prev.speed_known && !prev.lost && dt > 0 &&
             std::abs(f.speed - prev.speed) / dt > params_.lost_frame_max_acceleration) {
    // A lost or first frame has no trustworthy speed to compare against.
    f.lost = true;
    f.lost_reason = "acceleration " + std::to_string(std::abs(f.speed - prev.speed) / dt) + " m/s²";
  }

  const double aux_delta = f.delta;
  if (!f.lost && f.delta <= params_.new_frame_min_distance) {
    const bool stopped = std::abs(f.delta - last_processed_aux_delta_) < params_.frame_stopped_distance;
    stopped_in_a_row_ = stopped ? stopped_in_a_row_ + 1 : 0;
    f.kind = stopped ? FrameKind::kStopped : FrameKind::kDropped;
    if (stopped && stopped_in_a_row_ == params_.frames_since_stopped_force_frame)
      f.kind = FrameKind::kStoppedKeyframe;
  } else {
    stopped_in_a_row_ = 0;
    f.kind = FrameKind::kFrame;
  }

  if (f.kind == FrameKind::kFrame || f.kind == FrameKind::kStoppedKeyframe) {
    f.path_length = prev.path_length + f.delta;
    const MappingFrame& last_kf = frames_[keyframes_.back()];
    if (f.lost || f.path_length >= last_kf.path_length + params_.new_keyframe_min_distance)
      f.kind = f.kind == FrameKind::kStoppedKeyframe ? FrameKind::kStoppedKeyframe : FrameKind::kKeyframe;
    if (f.kind == FrameKind::kKeyframe && !f.lost) {
      if (auto reason = keyframeLostReason(f)) {
        f.lost = true;
        f.lost_reason = *reason;
      }
    }
    if (f.isKeyframe()) {
      f.keyframe_index = int(keyframes_.size());
      keyframes_.push_back(frames_.size());
    }
    frames_.push_back(f);
  } else {
    f.path_length = prev.path_length;
  }

  last_processed_ = f;
  last_processed_aux_delta_ = aux_delta;
  return f;
}

std::optional<std::string> FrameTracker::keyframeLostReason(const MappingFrame& candidate) const {
  const MappingFrame& kf = frames_[keyframes_.back()];
  // The keyframe-lost check looks for a registration jump. A turn is not one: on a turn the direction of
  // travel changes with the vehicle's heading, and between keyframes a metre apart a robot's 2-3 m radius
  // turns it by 20-30° (yard-side: 28°; its two keyframes there called lost took 15 of a side lidar's 50
  // calibration candidates with them). So both tests follow the vehicle's own motion: the travel direction
  // is compared as the vehicle sees it, and the frames between two keyframes must lie on the screw motion
  // between them (an arc on a turn).
  if (keyframes_.size() >= 2) {
    const MappingFrame& kf_prev = frames_[keyframes_[keyframes_.size() - 2]];
    const Eigen::Vector3d d1 = kf.T_map_lidar.translation() - kf_prev.T_map_lidar.translation();
    const Eigen::Vector3d d2 = candidate.T_map_lidar.translation() - kf.T_map_lidar.translation();
    // Only over real travel: between stopped keyframes the "direction" is registration noise.
    const double min_travel = 0.5 * params_.new_keyframe_min_distance;
    if (d1.norm() > min_travel && d2.norm() > min_travel) {
      // Each stretch's direction in the vehicle's frame halfway along it: constant on a turn of constant
      // radius, whatever the radius, and on a straight.
      const Eigen::Vector3d v1 =
          interpolateLerpSlerp(kf_prev.T_map_lidar, kf.T_map_lidar, 0.5).linear().transpose() * d1;
      const Eigen::Vector3d v2 =
          interpolateLerpSlerp(kf.T_map_lidar, candidate.T_map_lidar, 0.5).linear().transpose() * d2;
      double angle = rad2deg(std::acos(std::clamp(v1.normalized().dot(v2.normalized()), -1.0, 1.0)));
      // From rest a vehicle may set off backwards along the line it came (a car changes gear at rest):
      // after a stopped keyframe only the line of travel must hold, not its sense.
      if (kf.kind == FrameKind::kStoppedKeyframe) angle = std::min(angle, 180.0 - angle);
      if (angle > params_.lost_frame_max_angle_diff)
        return "direction of travel changed " + std::to_string(angle) + "° between keyframes (in the vehicle's frame)";
    }
  }
  // Frames between the two keyframes must lie on the screw motion between them, parametrised by path
  // length, not time: by time, every start from a stop (the speed changes between the keyframes) would be
  // "lost".
  const double span = candidate.path_length - kf.path_length;
  for (std::size_t i = keyframes_.back() + 1; i < frames_.size() && span > 0; ++i) {
    const MappingFrame& mid = frames_[i];
    const Pose expected =
        interpolateGeodesic(kf.T_map_lidar, candidate.T_map_lidar, (mid.path_length - kf.path_length) / span);
    const double error = (expected.translation() - mid.T_map_lidar.translation()).norm();
    if (error > params_.lost_frame_interpolation_error)
      return "frame " + std::to_string(mid.sequence) + " is " + std::to_string(error) +
             " m off the keyframe interpolation";
  }
  return std::nullopt;
}

}  // namespace rigcal::pipeline
