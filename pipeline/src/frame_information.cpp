#include "rigcal/pipeline/frame_information.hpp"

#include <Eigen/Eigenvalues>

#include <vector>

#include "rigcal/registration/nearest_neighbors.hpp"
#include "rigcal/registration/point_cloud.hpp"
#include "rigcal/registration/voxel_grid.hpp"

namespace rigcal::pipeline {

registration::PointToPlaneInformation frameInformation(const Scan& cloud, const FrameInformationOptions& options) {
  registration::PointToPlaneInformation info;
  const registration::PointCloud thinned = registration::voxelDownsample(registration::fromScan(cloud), options.leaf_size);
  if (thinned.size() < 3) return info;
  const registration::KdTree tree(thinned.points);
  std::vector<registration::Neighbor> nb(std::size_t(options.num_neighbors));
  const double max_sq = options.max_neighbor_distance * options.max_neighbor_distance;
  for (const Eigen::Vector4d& p : thinned.points) {
    const std::size_t n = tree.knn(p, nb.size(), nb.data(), max_sq);
    if (n < 5) continue;
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (std::size_t j = 0; j < n; ++j) mean += thinned.points[nb[j].index].head<3>();
    mean /= double(n);
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    for (std::size_t j = 0; j < n; ++j) {
      const Eigen::Vector3d d = thinned.points[nb[j].index].head<3>() - mean;
      cov += d * d.transpose();
    }
    // The closed form for 3x3 (several times cheaper than the iterative solver; its eigenvalues are accurate
    // far beyond the thresholds below).
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es;
    es.computeDirect(cov);
    const Eigen::Vector3d ev = es.eigenvalues();  // ascending
    if (ev(2) <= 0 || ev(0) > options.max_flatness * ev(1) || ev(1) < options.min_planarity * ev(2)) continue;
    info.add(p.head<3>(), es.eigenvectors().col(0));
  }
  return info;
}

}  // namespace rigcal::pipeline
