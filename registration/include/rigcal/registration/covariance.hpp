#pragma once
// Local surface shape from the k nearest neighbours of every point: a unit normal (smallest principal
// axis, turned towards the cloud's origin, i.e. the sensor) and a GICP covariance. The covariance is
// "plane-regularised" as in Segal et al. / PCL: unit variance along the surface, plane_epsilon along the
// normal, so point-to-plane-like residuals whatever the point density.
#include <cstddef>

#include "rigcal/registration/deadline.hpp"
#include "rigcal/registration/nearest_neighbors.hpp"
#include "rigcal/registration/point_cloud.hpp"

namespace rigcal::registration {

struct CovarianceOptions {
  int num_neighbors = 10;        // k; PCL GICP uses 20, small_gicp 10: about as accurate on our scans, half the cost
  double plane_epsilon = 1e-3;   // PCL GICP's gicp_epsilon
  int num_threads = 1;
  /// Once expired the rest of the work is skipped (between chunks of a few hundred points) and the
  /// normals/covariances are incomplete: a caller that set it checks it and discards the cloud.
  Deadline deadline;
};

struct CovarianceStats {
  std::size_t points = 0;
  std::size_t without_neighborhood = 0;  // < 3 neighbours: isotropic covariance, zero normal
};

/// Fills cloud.normals and cloud.covariances. `tree` must have been built over cloud.points.
/// With `graph`, also records each point's graph_degree nearest other points (from the same k-NN pass).
CovarianceStats estimateCovariances(PointCloud& cloud, const KdTree& tree, const CovarianceOptions& options = {},
                                    NeighborGraph* graph = nullptr, std::size_t graph_degree = 10);
/// Same, building a temporary tree over the cloud first.
CovarianceStats estimateCovariances(PointCloud& cloud, const CovarianceOptions& options = {});

}  // namespace rigcal::registration
