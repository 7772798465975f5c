#pragma once
// Exact nearest-neighbour search in 3-D: a flat, balanced kd-tree (median splits on the widest axis,
// small leaves, nodes in one array in pre-order). It keeps its own copy of the points in leaf order as
// float offsets from the cloud's centre, so leaves are contiguous in memory and far-from-origin (UTM) maps
// lose no precision. bench/registration_bench.cpp compares it with pcl::KdTreeFLANN.
// Immutable after construction: any number of threads may query one tree.
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include <Eigen/Core>

namespace rigcal::registration {

struct KdTreeOptions {
  std::size_t leaf_size = 12;  // points per leaf (bench: 8..16 are all within a few % of each other)
  int num_threads = 1;         // threads building the two halves below the root (result is identical)
};

struct Neighbor {
  std::uint32_t index = 0;  // into the point array the tree was built from
  float sq_distance = 0.0F;
};

/// Each point's nearest other points (a by-product of the covariance pass). Every point of the cloud
/// that is not listed for j is at least radius[j] from point j, which lets a search that starts at a
/// previous match prove its answer exact without touching the tree (see the ICP matcher).
///
/// A neighbour is stored as its offset from j, 2 bytes instead of a 4-byte index (issue #18: 20 of a
/// calibration target's ~150 bytes a point): a Target's points are in its tree's leaf order, so a point's
/// neighbours sit near it in the array. A point with a neighbour beyond ±32767 places lists itself instead
/// (offsets 0) and has radius 0, like a point with fewer than `degree` others: it vouches for nothing and
/// the tree answers its searches. The answers stay exact; only how often the tree is asked changes.
struct NeighborGraph {
  static constexpr std::int32_t kMaxOffset = 32767;
  std::size_t degree = 0;              // entries per point
  std::vector<std::int16_t> offsets;   // degree × size, closest first: neighbour r of j is j + offsets[j·degree + r]
  std::vector<float> radius;           // per point; 0 when it cannot vouch for anything

  [[nodiscard]] bool empty() const { return degree == 0 || radius.empty(); }
  /// Neighbour r (closest first) of point j; j itself where the list could not be stored.
  [[nodiscard]] std::uint32_t neighbor(std::size_t j, std::size_t r) const {
    return static_cast<std::uint32_t>(static_cast<std::int64_t>(j) + offsets[j * degree + r]);
  }
  /// Point j's list (`degree` entries, closest first) and the radius it vouches for; a list with an offset
  /// out of range is not stored (j then vouches for nothing). False when it was not.
  bool set(std::size_t j, const std::uint32_t* list, float radius_j) {
    std::int16_t* out = offsets.data() + j * degree;
    for (std::size_t r = 0; r < degree; ++r) {
      const std::int64_t d = static_cast<std::int64_t>(list[r]) - static_cast<std::int64_t>(j);
      if (d < -kMaxOffset || d > kMaxOffset) {
        for (std::size_t q = 0; q < degree; ++q) out[q] = 0;
        radius[j] = 0.0F;
        return false;
      }
      out[r] = static_cast<std::int16_t>(d);
    }
    radius[j] = radius_j;
    return true;
  }
};

class KdTree {
 public:
  static constexpr std::uint32_t kNoHint = std::numeric_limits<std::uint32_t>::max();

  KdTree() = default;
  /// Builds over the xyz of `points` (w is ignored); they must be finite. At most 2^32 − 2 points.
  explicit KdTree(std::span<const Eigen::Vector4d> points, const KdTreeOptions& options = {});

  [[nodiscard]] std::size_t size() const { return points_.size(); }
  [[nodiscard]] bool empty() const { return points_.empty(); }

  /// The nearest point closer than sqrt(max_sq_distance); false when there is none.
  /// `hint` (an index probably close to q, e.g. last iteration's match) only speeds the search up.
  /// With relative_error ε > 0 the answer may instead be any point at most (1 + ε) times as far as the
  /// nearest (and still within range): cells are skipped sooner, which pays for queries far from the
  /// points (a dense map around a source not yet aligned), where the ball to search holds many leaves.
  bool nearest(const Eigen::Vector4d& q, double max_sq_distance, Neighbor* out, std::uint32_t hint = kNoHint,
               float relative_error = 0.0F) const;

  /// Original index of the i-th point in leaf order. A cloud stored in this order makes spatially close
  /// queries touch close memory; see useLeafOrderIndices(). Empty once that has run.
  [[nodiscard]] const std::vector<std::uint32_t>& leafOrder() const { return index_; }
  /// After the caller has stored its points in leafOrder(), makes every index the tree reports (and
  /// takes as a hint) refer to that new order. The two index maps are then identities and are freed
  /// (8 bytes a point: ~17 MB over a calibration's targets).
  void useLeafOrderIndices();

  /// The tree's own copy of the points: float offsets (w = 0) from its centre, in leaf order, so entry i
  /// is the point the tree reports as i once useLeafOrderIndices() has run (as in a Target). Half the
  /// bytes of the double cloud: what a search that walks many points (the ICP matcher's graph) reads.
  [[nodiscard]] std::span<const Eigen::Vector4f> localPoints() const { return points_; }
  /// q in the frame of localPoints() (w = 0).
  [[nodiscard]] Eigen::Vector4f toLocal(const Eigen::Vector4d& q) const { return local(q); }

  /// Up to k nearest points closer than sqrt(max_sq_distance), closest first; returns how many.
  /// `hints` (distinct indices, e.g. last iteration's k nearest) seed the search; they only speed it up.
  std::size_t knn(const Eigen::Vector4d& q, std::size_t k, Neighbor* out,
                  double max_sq_distance = std::numeric_limits<double>::infinity(),
                  std::span<const std::uint32_t> hints = {}) const;

 private:
  struct Node {
    float lo = 0, hi = 0;      // inner: largest coordinate on `axis` in the left child, smallest in the right
    std::uint32_t begin = 0;   // points [begin, end) below this node
    std::uint32_t end = 0;
    std::uint32_t right = 0;   // inner: index of the right child (the left child follows this node)
    std::uint32_t axis = 3;    // 0..2, or 3 for a leaf
  };
  struct Build;

  [[nodiscard]] Eigen::Vector4f local(const Eigen::Vector4d& q) const;
  /// The caller's index of leaf-order position i, and back (identities once index_ / where_ are freed).
  [[nodiscard]] std::uint32_t originalIndex(std::uint32_t i) const { return index_.empty() ? i : index_[i]; }
  [[nodiscard]] std::uint32_t leafPosition(std::uint32_t original) const {
    return where_.empty() ? original : where_[original];
  }
  template <class Set>
  void search(const Eigen::Vector4f& q, Set& set) const;
  [[nodiscard]] float initialBound(const Eigen::Vector4f& q, float* off) const;

  Eigen::Vector3d center_ = Eigen::Vector3d::Zero();
  Eigen::Vector3f box_min_ = Eigen::Vector3f::Zero(), box_max_ = Eigen::Vector3f::Zero();
  std::vector<Eigen::Vector4f> points_;  // leaf order, relative to center_, w = 0
  std::vector<std::uint32_t> index_;     // leaf order → original index (empty: identity)
  std::vector<std::uint32_t> where_;     // original index → leaf order, for hints (empty: identity)
  std::vector<Node> nodes_;
};

}  // namespace rigcal::registration
