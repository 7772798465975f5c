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
  [[nodiscard]] bool contains(const Eigen::Vector3d& p) const {
    const Eigen::Array3d c = (p * inv_cell_).array().floor() - origin_;
    // Written so that NaN fails: outside the grid's box (or non-finite) is outside every cell.
    if (!((c >= 0.0).all() && (c < size_).all())) return false;
    const std::uint64_t i = (std::uint64_t(c.x()) * std::uint64_t(size_.y()) + std::uint64_t(c.y())) *
                                std::uint64_t(size_.z()) + std::uint64_t(c.z());
    if (!bits_.empty()) return (bits_[i >> 6] >> (i & 63)) & 1U;
    return cells_.count(i) != 0;
  }

  [[nodiscard]] std::size_t cells() const { return cell_count_; }

 private:
  double inv_cell_;
  // The cells, numbered within the box of cell coordinates they span: a bit each while that box is small
  // (a crop tests every point of a dozen mapping clouds, ~2.6 M on the street: a bit costs a load where a
  // hash set's lookup chased a node), a hash set of the numbers beyond it.
  Eigen::Array3d origin_ = Eigen::Array3d::Zero();  // the box's lowest cell
  Eigen::Array3d size_ = Eigen::Array3d::Zero();    // cells per axis
  std::vector<std::uint64_t> bits_;
  std::unordered_set<std::uint64_t> cells_;
  std::size_t cell_count_ = 0;
};

}  // namespace rigcal::calib
