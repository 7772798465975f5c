#pragma once
// The point-to-plane correspondences of a source under a pose: what both information measures of calib
// (registration_information.cpp: a registered pair's weak directions; frame_pose_information.cpp: a frame's
// weight in the verdict) sum over, so that they agree on what corresponds. Private to calib/.
#include <algorithm>
#include <cstddef>

#include <Eigen/Core>

#include "rigcal/core/pose.hpp"
#include "rigcal/registration/point_cloud.hpp"
#include "rigcal/registration/target.hpp"

namespace rigcal::calib::detail {

/// Calls fn(p, q, n) for every `stride`-th source point p whose image q = T·p has a target neighbour within
/// `max_distance` that has a normal n (all three in 3D; p in the source's frame, q and n in the target's).
template <class Fn>
void forEachPlaneCorrespondence(const registration::Target& target, const registration::PointCloud& source,
                                const Pose& T, double max_distance, std::size_t stride, Fn&& fn) {
  if (!target.hasNormals()) return;
  for (std::size_t i = 0; i < source.points.size(); i += std::max<std::size_t>(1, stride)) {
    const Eigen::Vector3d p = source.points[i].head<3>();
    const Eigen::Vector4d q = (T * p).homogeneous();
    registration::Neighbor nb;
    if (!target.tree().nearest(q, max_distance * max_distance, &nb)) continue;
    const Eigen::Vector3d n = target.normal(nb.index);
    if (n.squaredNorm() < 0.5) continue;  // no normal estimated there
    fn(p, Eigen::Vector3d(q.head<3>()), n);
  }
}

}  // namespace rigcal::calib::detail
