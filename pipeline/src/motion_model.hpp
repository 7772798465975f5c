#pragma once
// The mapper's motion model: constant velocity between the last two good registrations (mid-sweep poses
// and times), held still after a stopped frame. It follows the pure registration results only: were it
// fed the poses at a sweep's first point, which are extrapolated with the model's own velocity, a velocity
// error would come back amplified (the loop oscillates and grows while standing still).
// Private to the pipeline library.
#include "rigcal/core/pose.hpp"
#include "rigcal/core/scan.hpp"
#include "rigcal/pipeline/deskew.hpp"
#include "rigcal/pipeline/frame_tracker.hpp"

namespace rigcal::pipeline {

class MotionModel {
 public:
  /// The time a sweep is registered at: the middle of its points' times.
  static TimeNs midSweep(const Scan& scan) { return scan.stamp_ns + (scan.endTime() - scan.stamp_ns) / 2; }

  /// False until the first frame: no scan has been placed in the map yet.
  [[nodiscard]] bool started() const { return have_last_; }

  /// The sensor's motion around `stamp`, in the sensor frame at `stamp` (identity until two poses).
  [[nodiscard]] SensorMotion motion(TimeNs stamp) const;
  /// The registration guess at `mid`: the last pose after a stopped frame that registered, else the
  /// constant-velocity prediction (after a failed registration, the last two good ones still predict best).
  [[nodiscard]] Pose guess(TimeNs mid) const;

  /// With a registration accepted at `mid`: the sensor's motion from the last registration to this one,
  /// referenced at `t_ref` (false when there is no earlier registration to measure it from).
  [[nodiscard]] bool registeredMotion(TimeNs mid, const Pose& mid_pose, TimeNs t_ref, SensorMotion& out) const;

  /// An accepted registration: `mid_pose` at `mid` becomes the last pose.
  void registered(TimeNs mid, const Pose& mid_pose);
  /// The tracker's verdict on the frame; the first frame (`T_map_lidar` at `scan`'s stamp) starts the model.
  void classified(const Scan& scan, const Pose& T_map_lidar, FrameKind kind, bool registration_ok);

 private:
  [[nodiscard]] Pose extrapolate(TimeNs stamp) const;

  bool have_last_ = false, have_prev_ = false, last_failed_ = false;
  FrameKind last_kind_ = FrameKind::kKeyframe;
  TimeNs last_stamp_ = 0, prev_stamp_ = 0;
  Pose last_pose_ = Pose::Identity(), prev_pose_ = Pose::Identity();
};

}  // namespace rigcal::pipeline
