#include "trajectory_buffer.hpp"

#include "rigcal/pipeline/deskew.hpp"

#include <algorithm>

namespace rigcal::pipeline {

void TrajectoryBuffer::add(TimeNs stamp, const Pose& T_map_lidar) {
  if (!stamps_.empty() && stamp <= stamps_.back()) return;  // time order only
  stamps_.push_back(stamp);
  poses_.push_back(T_map_lidar);
}

Pose TrajectoryBuffer::at(TimeNs t) const {
  return poseOnTrajectory(
      stamps_.size(), [&](std::size_t i) { return stamps_[i]; }, [&](std::size_t i) { return poses_[i]; }, t);
}

void TrajectoryBuffer::trimBefore(TimeNs t) {
  const auto after = std::upper_bound(stamps_.begin(), stamps_.end(), t);
  if (after - stamps_.begin() <= 1) return;
  const auto n = (after - stamps_.begin()) - 1;
  stamps_.erase(stamps_.begin(), stamps_.begin() + n);
  poses_.erase(poses_.begin(), poses_.begin() + n);
}

}  // namespace rigcal::pipeline
