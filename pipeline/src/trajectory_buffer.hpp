#pragma once
// The mapping lidar's registered poses in time order, interpolated at any time by poseOnTrajectory()
// (deskew.hpp: the same rule as calibration's re-deskew). Owned by one stage thread.
#include <vector>

#include "rigcal/core/pose.hpp"
#include "rigcal/core/time.hpp"

namespace rigcal::pipeline {

class TrajectoryBuffer {
 public:
  void add(TimeNs stamp, const Pose& T_map_lidar);
  [[nodiscard]] bool empty() const { return stamps_.empty(); }
  [[nodiscard]] TimeNs last() const { return stamps_.back(); }
  [[nodiscard]] Pose at(TimeNs t) const;
  /// Forgets poses before `t`, keeping the one just before it.
  void trimBefore(TimeNs t);

 private:
  std::vector<TimeNs> stamps_;
  std::vector<Pose> poses_;
};

}  // namespace rigcal::pipeline
