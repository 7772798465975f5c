#pragma once
// Where a calibration source lies in the mapping frame under a few candidate extrinsics, dilated by a
// radius: once the extrinsic is known to within the registrators' reach, a target needs only the mapping
// points near the source, not the whole box under the initial guess (most of the scene for a 360° lidar).
#include <cstdint>
#include <unordered_set>
#include <vector>

#include <Eigen/Core>

#include "rigcal/core/pose.hpp"
#include "rigcal/registration/point_cloud.hpp"

namespace rigcal::calib {

class SourceNeighbourhood {
 public:
  /// The cells (of size `radius`) that hold a source point under one of `poses`, and their 26 neighbours.
  /// `radius` must be positive.
  SourceNeighbourhood(const registration::PointCloud& source, const std::vector<Pose>& poses, double radius);

  /// True for every point within `radius` of a placed source point (and some up to 2·√3·radius away).
  [[nodiscard]] bool contains(const Eigen::Vector3d& p) const { return cells_.count(key(p)) != 0; }

  [[nodiscard]] std::size_t cells() const { return cells_.size(); }

 private:
  [[nodiscard]] std::uint64_t key(const Eigen::Vector3d& p) const;
  static std::uint64_t pack(std::int64_t x, std::int64_t y, std::int64_t z);

  double inv_cell_;
  std::unordered_set<std::uint64_t> cells_;
};

}  // namespace rigcal::calib
