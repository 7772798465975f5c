#pragma once
// A Target's covariance pass: the same normals, neighbour graph and covariances as estimateCovariances,
// but the covariances written straight into the compact float form the Target keeps (issue #18: the
// 4x4 matrices, 128 bytes a point, were most of the peak of a target's build).
#include <cstddef>
#include <vector>

#include "rigcal/registration/covariance.hpp"

namespace rigcal::registration::detail {

/// Fills cloud.normals (cloud.covariances stays empty) and `upper`: each covariance's (xx, xy, xz, yy, yz,
/// zz) as float, 6 a point, each the float of what estimateCovariances would put in the 4x4 matrix.
CovarianceStats estimateCompactCovariances(PointCloud& cloud, const KdTree& tree, const CovarianceOptions& options,
                                           NeighborGraph* graph, std::size_t graph_degree, std::vector<float>* upper);

}  // namespace rigcal::registration::detail
