#include "motion_model.hpp"

namespace rigcal::pipeline {

Pose MotionModel::extrapolate(TimeNs stamp) const {
  if (!have_prev_ || last_stamp_ <= prev_stamp_) return last_pose_;
  const double steps = double(stamp - last_stamp_) / double(last_stamp_ - prev_stamp_);
  return last_pose_ * expSE3(steps * logSE3(prev_pose_.inverse() * last_pose_));
}

SensorMotion MotionModel::motion(TimeNs stamp) const {
  if (!have_prev_ || last_stamp_ <= prev_stamp_) return [](TimeNs) { return Pose::Identity(); };
  return constantVelocity(prev_pose_.inverse() * last_pose_, last_stamp_ - prev_stamp_, stamp);
}

Pose MotionModel::guess(TimeNs mid) const {
  const bool hold = (last_kind_ == FrameKind::kStopped || last_kind_ == FrameKind::kStoppedKeyframe) && !last_failed_;
  return hold ? last_pose_ : extrapolate(mid);
}

bool MotionModel::registeredMotion(TimeNs mid, const Pose& mid_pose, TimeNs t_ref, SensorMotion& out) const {
  if (!have_last_ || mid <= last_stamp_) return false;
  out = constantVelocity(last_pose_.inverse() * mid_pose, mid - last_stamp_, t_ref);
  return true;
}

void MotionModel::registered(TimeNs mid, const Pose& mid_pose) {
  prev_pose_ = last_pose_;
  prev_stamp_ = last_stamp_;
  have_prev_ = have_last_;
  last_pose_ = mid_pose;
  last_stamp_ = mid;
  have_last_ = true;
}

void MotionModel::classified(const Scan& scan, const Pose& T_map_lidar, FrameKind kind, bool registration_ok) {
  last_failed_ = !registration_ok;
  last_kind_ = kind;
  if (!have_last_) {  // the first frame: at rest as far as anyone knows
    last_pose_ = T_map_lidar;
    last_stamp_ = midSweep(scan);
    have_last_ = true;
  }
}

}  // namespace rigcal::pipeline
