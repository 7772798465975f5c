#include "rigcal/registration/covariance.hpp"

#include <algorithm>
#include <cmath>
#include <atomic>
#include <vector>

#include <Eigen/Eigenvalues>

#include "cell_knn.hpp"
#include "compact_covariances.hpp"
#include "offset_sums.hpp"
#include "rigcal/registration/parallel.hpp"

namespace rigcal::registration {

namespace {

// Unit eigenvector of the smallest eigenvalue of a symmetric 3x3 matrix. Only that one is needed, so
// instead of a full decomposition (Eigen's computeDirect: ~1.1k instructions, a third of them atan2 and
// sincos) the eigenvalues come from the trigonometric closed form and the vector from the largest cross
// product of two rows of (C − λ_min·I). Where the two smallest eigenvalues nearly coincide (a line, a
// blob: the normal is ill-defined and the cross products lose precision) Eigen's solver decides, as before.
Eigen::Vector3d smallestEigenvector(const Eigen::Matrix3d& c) {
  const double mean = c.trace() / 3.0;
  Eigen::Matrix3d b = c;
  b.diagonal().array() -= mean;
  const double p = std::sqrt(b.squaredNorm() / 6.0);
  if (p > 1e-150 * std::max(1.0, std::abs(mean))) {
    const double half_det = (b / p).determinant() / 2.0;
    // φ in [0, π/3]; cos(φ + 2π/3) = −cos φ / 2 − sin φ·√3/2 spares a second cosine.
    const double cos_phi = std::cos(std::acos(std::clamp(half_det, -1.0, 1.0)) / 3.0);
    const double sin_phi = std::sqrt(std::max(0.0, 1.0 - cos_phi * cos_phi));
    const double largest = mean + 2.0 * p * cos_phi;
    const double smallest = mean - p * (cos_phi + 1.7320508075688772935 * sin_phi);
    const double middle = 3.0 * mean - largest - smallest;
    if (middle - smallest > 1e-3 * (largest - smallest)) {
      Eigen::Matrix3d m = c;
      m.diagonal().array() -= smallest;
      const Eigen::Vector3d c01 = m.row(0).cross(m.row(1)), c02 = m.row(0).cross(m.row(2)),
                            c12 = m.row(1).cross(m.row(2));
      const double n01 = c01.squaredNorm(), n02 = c02.squaredNorm(), n12 = c12.squaredNorm();
      const Eigen::Vector3d& best = n01 >= n02 ? (n01 >= n12 ? c01 : c12) : (n02 >= n12 ? c02 : c12);
      const double best_norm = std::max({n01, n02, n12});
      if (best_norm > 0.0 && std::isfinite(best_norm)) return best / std::sqrt(best_norm);
    }
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
  eig.computeDirect(c);
  return eig.eigenvectors().col(0);
}

// Where the shapes go: the cloud's 4x4 covariances, or (a Target's build, which keeps nothing else) each
// covariance's upper triangle in float, 6 a point, without the 128-byte matrices ever existing.
struct ShapeSink {
  PointCloud* cloud = nullptr;
  float* upper = nullptr;  // non-null: the compact form instead of cloud->covariances

  void covariance(std::size_t i, const Eigen::Matrix3d& c) const {
    if (upper == nullptr) {
      cloud->covariances[i].topLeftCorner<3, 3>() = c;
      return;
    }
    float* u = upper + 6 * i;
    u[0] = static_cast<float>(c(0, 0));
    u[1] = static_cast<float>(c(0, 1));
    u[2] = static_cast<float>(c(0, 2));
    u[3] = static_cast<float>(c(1, 1));
    u[4] = static_cast<float>(c(1, 2));
    u[5] = static_cast<float>(c(2, 2));
  }
};

// Normal and plane-regularised covariance of point i from its `found` nearest (the point itself among
// them); false (isotropic, no normal) with fewer than 3.
bool fillShape(const ShapeSink& sink, std::size_t i, const Neighbor* nb, std::size_t found, double plane_epsilon) {
  PointCloud& cloud = *sink.cloud;
  if (found < 3) {
    sink.covariance(i, Eigen::Matrix3d::Identity());
    return false;
  }
  // One pass of sums relative to the point itself (offsets of a neighbourhood: exact enough in double
  // even far from the origin), then cov = E[d·dᵀ] − E[d]·E[d]ᵀ.
  static const detail::OffsetSumsKernel offset_sums = detail::fastestOffsetSums();
  detail::OffsetSums sums;
  offset_sums(cloud.points.data(), nb, found, cloud.points[i], &sums);
  const double sx = sums.s[0], sy = sums.s[1], sz = sums.s[2];
  const double sxx = sums.x[0], sxy = sums.x[1], sxz = sums.x[2], syy = sums.yz[0], syz = sums.yz[1], szz = sums.yz[2];
  const double inv = 1.0 / static_cast<double>(found);
  const double mx = sx * inv, my = sy * inv, mz = sz * inv;
  Eigen::Matrix3d cov;
  cov(0, 0) = sxx * inv - mx * mx;
  cov(0, 1) = cov(1, 0) = sxy * inv - mx * my;
  cov(0, 2) = cov(2, 0) = sxz * inv - mx * mz;
  cov(1, 1) = syy * inv - my * my;
  cov(1, 2) = cov(2, 1) = syz * inv - my * mz;
  cov(2, 2) = szz * inv - mz * mz;
  // U·diag(ε, 1, 1)·Uᵀ = I − (1 − ε)·n·nᵀ for orthonormal U: only the normal is needed.
  Eigen::Vector3d normal = smallestEigenvector(cov);
  sink.covariance(i, Eigen::Matrix3d::Identity() - (1.0 - plane_epsilon) * (normal * normal.transpose()));
  if (normal.dot(cloud.points[i].head<3>()) > 0.0) normal = -normal;  // face the sensor at the origin
  cloud.normals[i].head<3>() = normal;
  return true;
}

// Every point's k nearest (itself among them), closest first: the cell grid for all it can prove, the
// tree for the rest (sparse outskirts) or for everything when a grid does not suit the cloud. `tree`, when
// given, must be over cloud.points; otherwise one is built only if some point needs it.
detail::CellKnn allNearest(const PointCloud& cloud, std::size_t k, int num_threads, const KdTree* tree,
                           const Deadline& stop = {}) {
  const std::size_t n = cloud.size();
  detail::CellKnn knn;
  const bool grid = detail::cellKnn(cloud.points, k, num_threads, tree != nullptr, &knn, stop);
  if (!grid) {
    knn.k = k;
    knn.neighbors.assign(n * k, Neighbor{});
    knn.count.assign(n, 0);
    knn.unproven.resize(n);
    for (std::size_t i = 0; i < n; ++i) knn.unproven[i] = static_cast<std::uint32_t>(i);
  }
  if (knn.unproven.empty()) return knn;
  KdTree own;
  if (tree == nullptr) {
    KdTreeOptions tree_options;
    tree_options.num_threads = num_threads;
    own = KdTree(cloud.points, tree_options);
    tree = &own;
  }
  const std::size_t m = knn.unproven.size();
  parallelFor(chunkCount(m, kDefaultChunk), num_threads, [&](std::size_t task) {
    if (stop.expired()) return;  // left without neighbours: the caller discards the result
    for (std::size_t u = task * kDefaultChunk; u < std::min(m, (task + 1) * kDefaultChunk); ++u) {
      const std::uint32_t i = knn.unproven[u];
      knn.count[i] = static_cast<std::uint32_t>(tree->knn(cloud.points[i], k, knn.neighbors.data() + i * k));
    }
  });
  knn.unproven.clear();
  return knn;
}

// Normals and covariances from the first k of each point's neighbours and, with `graph`, its first
// `degree` other points; the next other point bounds the distance of everything not listed: that is the
// radius the list vouches for.
CovarianceStats shapesAndGraph(PointCloud& cloud, const detail::CellKnn& knn, std::size_t k,
                               const CovarianceOptions& options, NeighborGraph* graph, std::size_t degree,
                               std::vector<float>* upper = nullptr) {
  const std::size_t n = cloud.size();
  const std::size_t k_query = knn.k;
  if (graph != nullptr) {
    graph->degree = degree;
    graph->offsets.assign(n * degree, 0);
    graph->radius.assign(n, 0.0F);
  }
  cloud.normals.assign(n, Eigen::Vector4d::Zero());
  ShapeSink sink{&cloud, nullptr};
  if (upper != nullptr) {
    std::vector<Eigen::Matrix4d>().swap(cloud.covariances);
    upper->assign(6 * n, 0.0F);
    sink.upper = upper->data();
  } else {
    cloud.covariances.assign(n, Eigen::Matrix4d::Zero());
  }
  std::atomic<std::size_t> isolated{0};
  parallelFor(chunkCount(n, kDefaultChunk), options.num_threads, [&](std::size_t task) {
    if (options.deadline.expired()) return;
    std::size_t local_isolated = 0;
    std::vector<std::uint32_t> list;
    for (std::size_t i = task * kDefaultChunk; i < std::min(n, (task + 1) * kDefaultChunk); ++i) {
      const Neighbor* nb = knn.neighbors.data() + i * k_query;
      const std::size_t all = knn.count[i];
      if (degree > 0) {
        list.resize(degree);
        std::size_t m = 0, next = all;
        for (std::size_t j = 0; j < all; ++j) {
          if (nb[j].index == i) continue;
          if (m == degree) {
            next = j;
            break;
          }
          list[m++] = nb[j].index;
        }
        // Fewer than `degree` others, or none beyond them: the list vouches for nothing (radius stays 0).
        if (m == degree && next < all) graph->set(i, list.data(), std::sqrt(nb[next].sq_distance));
      }
      if (!fillShape(sink, i, nb, std::min(all, k), options.plane_epsilon)) ++local_isolated;
    }
    isolated.fetch_add(local_isolated, std::memory_order_relaxed);
  });
  return {n, isolated.load()};
}

// The k-NN pass over `tree` and the shapes (and graph) from it, into cloud.covariances or `upper`.
CovarianceStats shapesWithTree(PointCloud& cloud, const KdTree& tree, const CovarianceOptions& options,
                               NeighborGraph* graph, std::size_t graph_degree, std::vector<float>* upper) {
  const std::size_t k = static_cast<std::size_t>(std::max(options.num_neighbors, 3));
  const std::size_t degree = graph != nullptr ? graph_degree : 0;
  const std::size_t k_query = std::max(k, degree + 2);  // the graph wants itself, `degree` others and the next
  const detail::CellKnn knn = allNearest(cloud, k_query, options.num_threads, &tree, options.deadline);
  if (options.deadline.expired()) return {cloud.size(), 0};  // incomplete neighbours: never read them
  return shapesAndGraph(cloud, knn, k, options, graph, degree, upper);
}

}  // namespace

CovarianceStats estimateCovariances(PointCloud& cloud, const KdTree& tree, const CovarianceOptions& options,
                                    NeighborGraph* graph, std::size_t graph_degree) {
  return shapesWithTree(cloud, tree, options, graph, graph_degree, nullptr);
}

CovarianceStats detail::estimateCompactCovariances(PointCloud& cloud, const KdTree& tree,
                                                   const CovarianceOptions& options, NeighborGraph* graph,
                                                   std::size_t graph_degree, std::vector<float>* upper) {
  return shapesWithTree(cloud, tree, options, graph, graph_degree, upper);
}

CovarianceStats estimateCovariances(PointCloud& cloud, const CovarianceOptions& options) {
  const std::size_t k = static_cast<std::size_t>(std::max(options.num_neighbors, 3));
  const detail::CellKnn knn = allNearest(cloud, k, options.num_threads, nullptr);
  return shapesAndGraph(cloud, knn, k, options, nullptr, 0);
}

}  // namespace rigcal::registration
