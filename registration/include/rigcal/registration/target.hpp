#pragma once
// Everything a registration needs from its target, built once: the cloud, its kd-tree, and on request
// normals + GICP covariances and NDT grids. Immutable after construction, so one Target (typically held
// in a std::shared_ptr<const Target>) serves any number of registrations on any number of threads.
#include <cstddef>
#include <span>
#include <vector>

#include "rigcal/registration/covariance.hpp"
#include "rigcal/registration/nearest_neighbors.hpp"
#include "rigcal/registration/ndt_grid.hpp"
#include "rigcal/registration/point_cloud.hpp"

namespace rigcal::registration {

struct TargetOptions {
  bool normals_and_covariances = false;  // needed by point-to-plane ICP and GICP
  /// The NeighborGraph that lets ICP/GICP re-match without the tree. Always built (for free) with the
  /// covariances; set this to also build it for a target without them (one k-NN pass).
  bool neighbor_graph = false;
  std::size_t neighbor_graph_degree = 10;
  std::vector<double> ndt_resolutions;   // one NdtGrid per entry (NDT needs the one it is run with)
  CovarianceOptions covariance;          // its num_threads is overridden by num_threads below
  NdtGridOptions ndt;                    // its resolution is overridden by each entry above
  KdTreeOptions tree;
  int num_threads = 1;
  /// A build that would outlast a calibration's deadline stops once this expires (between its steps and
  /// between chunks of the neighbour search and covariances) and leaves an incomplete target: stopped().
  Deadline deadline;
};

class Target {
 public:
  Target() = default;
  /// Drops non-finite points (which invalidates normals/covariances the cloud came with), then builds
  /// the tree and whatever `options` asks for that the cloud does not already carry. The points are
  /// stored in the tree's leaf order (neighbours close in memory: fewer cache misses when matching), so
  /// cloud() indices differ from the input's.
  explicit Target(PointCloud cloud, const TargetOptions& options = {});

  /// Positions only: normals are normal(i), covariances covarianceUpperFloat().
  [[nodiscard]] const PointCloud& cloud() const { return cloud_; }
  [[nodiscard]] const KdTree& tree() const { return tree_; }
  [[nodiscard]] std::size_t size() const { return cloud_.size(); }
  [[nodiscard]] bool empty() const { return cloud_.empty(); }
  [[nodiscard]] bool hasNormals() const { return !cloud_.empty() && normals_float_.size() == cloud_.size(); }
  /// The unit normal at cloud() point i (zero where none is known); requires hasNormals(). Kept in float
  /// (12 bytes a point instead of a Vector4d's 32, issue #18): a unit vector's float rounding (6e-8) moves a
  /// point-to-plane residual by less than a nanometre over the half metre a correspondence may span.
  [[nodiscard]] Eigen::Vector3d normal(std::size_t i) const { return normals_float_[i].cast<double>(); }
  [[nodiscard]] bool hasCovariances() const { return !covariance_upper_float_.empty(); }
  /// Empty unless built (see TargetOptions::neighbor_graph).
  [[nodiscard]] const NeighborGraph& neighborGraph() const { return graph_; }
  /// The grid built for this resolution (within 1e-9 m), or nullptr.
  [[nodiscard]] const NdtGrid* ndtGrid(double resolution) const;
  [[nodiscard]] std::size_t droppedNonFinite() const { return dropped_; }
  /// TargetOptions::deadline expired during the build: the target is incomplete and must not be used.
  [[nodiscard]] bool stopped() const { return stopped_; }
  /// Each covariance's upper triangle (xx, xy, xz, yy, yz, zz) in float, 6 per point in cloud() order, or
  /// empty without covariances: the only form kept (24 bytes a point instead of a Matrix4d's 128), which
  /// keeps a calibration's targets small and more of a dense map's covariances in GICP's cache. Their
  /// entries are O(1) (plane-regularised), so float loses nothing a GICP weight needs.
  [[nodiscard]] std::span<const float> covarianceUpperFloat() const { return covariance_upper_float_; }

 private:
  PointCloud cloud_;
  KdTree tree_;
  NeighborGraph graph_;
  std::vector<NdtGrid> grids_;
  std::size_t dropped_ = 0;
  bool stopped_ = false;
  std::vector<float> covariance_upper_float_;
  std::vector<Eigen::Vector3f> normals_float_;
};

/// One (source, target) pair of a batched registration or evaluation. Non-owning.
struct SourceTarget {
  const PointCloud* source = nullptr;
  const Target* target = nullptr;
};

}  // namespace rigcal::registration
