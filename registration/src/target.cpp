#include "rigcal/registration/target.hpp"

#include <cmath>

#include "compact_covariances.hpp"

namespace rigcal::registration {

Target::Target(PointCloud cloud, const TargetOptions& options) : cloud_(std::move(cloud)) {
  if (!allFinite(cloud_)) {
    PointCloud clean;
    clean.points.reserve(cloud_.size());
    for (const auto& p : cloud_.points) {
      if (p.head<3>().allFinite()) {
        clean.points.push_back(p);
      } else {
        ++dropped_;
      }
    }
    clean.points.shrink_to_fit();
    cloud_ = std::move(clean);
  }
  for (auto& p : cloud_.points) p.w() = 1.0;  // the residual code relies on homogeneous points
  KdTreeOptions tree_options = options.tree;
  tree_options.num_threads = options.num_threads;
  tree_ = KdTree(cloud_.points, tree_options);
  if (options.deadline.expired()) {
    stopped_ = true;
    return;
  }
  const std::vector<std::uint32_t>& order = tree_.leafOrder();
  PointCloud sorted;
  sorted.points.resize(order.size());
  for (std::size_t i = 0; i < order.size(); ++i) sorted.points[i] = cloud_.points[order[i]];
  if (cloud_.hasNormals()) {
    sorted.normals.resize(order.size());
    for (std::size_t i = 0; i < order.size(); ++i) sorted.normals[i] = cloud_.normals[order[i]];
  }
  if (cloud_.hasCovariances()) {
    sorted.covariances.resize(order.size());
    for (std::size_t i = 0; i < order.size(); ++i) sorted.covariances[i] = cloud_.covariances[order[i]];
  }
  cloud_ = std::move(sorted);
  tree_.useLeafOrderIndices();
  const bool want_graph = options.neighbor_graph || options.normals_and_covariances;
  if (!cloud_.empty() && (want_graph || options.normals_and_covariances)) {
    CovarianceOptions cov = options.covariance;
    cov.num_threads = options.num_threads;
    cov.deadline = options.deadline;
    if (options.normals_and_covariances && !(cloud_.hasNormals() && cloud_.hasCovariances())) {
      detail::estimateCompactCovariances(cloud_, tree_, cov, &graph_, options.neighbor_graph_degree,
                                         &covariance_upper_float_);
    } else {
      // Only the graph is missing: run the same k-NN pass on a scratch copy and keep the cloud's own
      // normals and covariances.
      PointCloud scratch;
      scratch.points = cloud_.points;
      cov.num_neighbors = static_cast<int>(options.neighbor_graph_degree) + 2;
      estimateCovariances(scratch, tree_, cov, &graph_, options.neighbor_graph_degree);
    }
  }
  if (options.deadline.expired()) {
    stopped_ = true;
    return;
  }
  if (cloud_.hasNormals()) {
    normals_float_.reserve(cloud_.size());
    for (const Eigen::Vector4d& n : cloud_.normals) normals_float_.push_back(n.head<3>().cast<float>());
    std::vector<Eigen::Vector4d>().swap(cloud_.normals);
  }
  if (cloud_.hasCovariances()) {
    // Covariances the cloud came with. Only the compact float form is read (GICP): the 4x4 matrices
    // (128 bytes a point) are dropped, which on a calibration's ~10 targets is most of its memory.
    covariance_upper_float_.reserve(6 * cloud_.size());
    for (const Eigen::Matrix4d& c : cloud_.covariances) {
      for (const double v : {c(0, 0), c(0, 1), c(0, 2), c(1, 1), c(1, 2), c(2, 2)}) {
        covariance_upper_float_.push_back(static_cast<float>(v));
      }
    }
    std::vector<Eigen::Matrix4d>().swap(cloud_.covariances);
  }
  for (const double resolution : options.ndt_resolutions) {
    if (ndtGrid(resolution) != nullptr) continue;
    if (options.deadline.expired()) {
      stopped_ = true;
      return;
    }
    NdtGridOptions ndt = options.ndt;
    ndt.resolution = resolution;
    grids_.emplace_back(cloud_, ndt);
  }
}

const NdtGrid* Target::ndtGrid(double resolution) const {
  for (const auto& g : grids_) {
    if (std::abs(g.resolution() - resolution) <= 1e-9) return &g;
  }
  return nullptr;
}

}  // namespace rigcal::registration
