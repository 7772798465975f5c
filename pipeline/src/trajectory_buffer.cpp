#include "trajectory_buffer.hpp"

#include <algorithm>

namespace rigcal::pipeline {

void TrajectoryBuffer::add(TimeNs stamp, const Pose& T_map_lidar) {
  if (!stamps_.empty() && stamp <= stamps_.back()) return;  // time order only
  stamps_.push_back(stamp);
  poses_.push_back(T_map_lidar);
}

Pose TrajectoryBuffer::at(TimeNs t) const {
  if (stamps_.empty()) return Pose::Identity();
  const auto after = std::upper_bound(stamps_.begin(), stamps_.end(), t);
  if (after == stamps_.begin()) return poses_.front();
  if (after == stamps_.end()) return poses_.back();
  const std::size_t r = std::size_t(after - stamps_.begin());
  return interpolateAt(stamps_[r - 1], poses_[r - 1], stamps_[r], poses_[r], t);
}

void TrajectoryBuffer::trimBefore(TimeNs t) {
  const auto after = std::upper_bound(stamps_.begin(), stamps_.end(), t);
  if (after - stamps_.begin() <= 1) return;
  const auto n = (after - stamps_.begin()) - 1;
  stamps_.erase(stamps_.begin(), stamps_.begin() + n);
  poses_.erase(poses_.begin(), poses_.begin() + n);
}

}  // namespace rigcal::pipeline
