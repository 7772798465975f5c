#include "rigcal/registration/covariance.hpp"

#include <algorithm>
#include <cmath>
#include <atomic>
#include <vector>

#include <Eigen/Eigenvalues>

#include "rigcal/registration/parallel.hpp"

namespace rigcal::registration {

CovarianceStats estimateCovariances(PointCloud& cloud, const KdTree& tree, const CovarianceOptions& options,
                                    NeighborGraph* graph, std::size_t graph_degree) {
  const std::size_t n = cloud.size();
  const std::size_t k = static_cast<std::size_t>(std::max(options.num_neighbors, 3));
  const std::size_t degree = graph != nullptr ? graph_degree : 0;
  const std::size_t k_query = std::max(k, degree + 2);  // the graph may want more points than the covariance
  if (graph != nullptr) {
    graph->degree = degree;
    graph->neighbors.assign(n * degree, 0);
    graph->radius.assign(n, 0.0F);
  }
  cloud.normals.assign(n, Eigen::Vector4d::Zero());
  cloud.covariances.assign(n, Eigen::Matrix4d::Zero());
  std::atomic<std::size_t> isolated{0};

  parallelFor(chunkCount(n, kDefaultChunk), options.num_threads, [&](std::size_t task) {
    std::vector<Neighbor> nb(k_query);
    const std::size_t begin = task * kDefaultChunk;
    const std::size_t end = std::min(n, begin + kDefaultChunk);
    std::size_t local_isolated = 0;
    for (std::size_t i = begin; i < end; ++i) {
      const std::size_t all = tree.knn(cloud.points[i], k_query, nb.data());
      if (degree > 0) {
        // Sorted by distance; list the first `degree` others. The next other point bounds the distance
        // of everything not listed: that is the radius the list vouches for.
        std::uint32_t* list = graph->neighbors.data() + i * degree;
        std::size_t m = 0, next = all;
        for (std::size_t j = 0; j < all; ++j) {
          if (nb[j].index == i) continue;
          if (m == degree) {
            next = j;
            break;
          }
          list[m++] = nb[j].index;
        }
        if (m == degree && next < all) graph->radius[i] = std::sqrt(nb[next].sq_distance);
      }
      const std::size_t found = std::min(all, k);  // the covariance uses the k nearest only
      if (found < 3) {
        cloud.covariances[i].topLeftCorner<3, 3>().setIdentity();
        ++local_isolated;
        continue;
      }
      // Centred two-pass sums: exact enough in double even for points far from the origin.
      Eigen::Vector3d mean = Eigen::Vector3d::Zero();
      for (std::size_t j = 0; j < found; ++j) mean += cloud.points[nb[j].index].head<3>();
      mean /= static_cast<double>(found);
      Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
      for (std::size_t j = 0; j < found; ++j) {
        const Eigen::Vector3d d = cloud.points[nb[j].index].head<3>() - mean;
        cov.noalias() += d * d.transpose();
      }
      cov /= static_cast<double>(found);
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
      eig.computeDirect(cov);
      // U·diag(ε, 1, 1)·Uᵀ = I − (1 − ε)·n·nᵀ for orthonormal U: only the normal is needed.
      Eigen::Vector3d normal = eig.eigenvectors().col(0);
      cloud.covariances[i].topLeftCorner<3, 3>() =
          Eigen::Matrix3d::Identity() - (1.0 - options.plane_epsilon) * (normal * normal.transpose());
      if (normal.dot(cloud.points[i].head<3>()) > 0.0) normal = -normal;  // face the sensor at the origin
      cloud.normals[i].head<3>() = normal;
    }
    isolated.fetch_add(local_isolated, std::memory_order_relaxed);
  });
  return {n, isolated.load()};
}

CovarianceStats estimateCovariances(PointCloud& cloud, const CovarianceOptions& options) {
  KdTreeOptions tree_options;
  tree_options.num_threads = options.num_threads;
  const KdTree tree(cloud.points, tree_options);
  return estimateCovariances(cloud, tree, options);
}

}  // namespace rigcal::registration
