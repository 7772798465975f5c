#include "rigcal/registration/nearest_neighbors.hpp"

#include <algorithm>
#include <stdexcept>
#include <thread>

#include "top_k.hpp"

namespace rigcal::registration {

namespace {
constexpr std::uint32_t kLeaf = 3;

// Nodes below a subtree of n points. Depends on n only, so both halves of a split can be built at the
// same time into their known, disjoint ranges of the pre-order array.
std::uint32_t nodeCount(std::size_t n, std::size_t leaf) {
  if (n <= leaf) return 1;
  return 1 + nodeCount(n / 2, leaf) + nodeCount(n - n / 2, leaf);
}

float toFloat(double v) {
  if (v >= static_cast<double>(std::numeric_limits<float>::max())) return std::numeric_limits<float>::max();
  return static_cast<float>(v);
}
}  // namespace

struct KdTree::Build {
  const std::vector<Eigen::Vector4f>& pts;  // original order
  std::vector<std::uint32_t>& perm;
  std::vector<Node>& nodes;
  std::size_t leaf;

  void run(std::uint32_t id, std::uint32_t begin, std::uint32_t end, int threads) {
    Node& node = nodes[id];
    node.begin = begin;
    node.end = end;
    const std::size_t n = end - begin;
    if (n <= leaf) {
      node.axis = kLeaf;
      return;
    }
    Eigen::Array3f lo = Eigen::Array3f::Constant(std::numeric_limits<float>::max());
    Eigen::Array3f hi = -lo;
    for (std::uint32_t i = begin; i < end; ++i) {
      lo = lo.min(pts[perm[i]].head<3>().array());
      hi = hi.max(pts[perm[i]].head<3>().array());
    }
    Eigen::Index axis = 0;
    (hi - lo).maxCoeff(&axis);
    const auto a = static_cast<std::uint32_t>(axis);
    const std::uint32_t mid = begin + static_cast<std::uint32_t>(n / 2);
    std::nth_element(perm.begin() + begin, perm.begin() + mid, perm.begin() + end,
                     [&](std::uint32_t l, std::uint32_t r) { return pts[l][a] < pts[r][a]; });
    float left_max = -std::numeric_limits<float>::max();
    for (std::uint32_t i = begin; i < mid; ++i) left_max = std::max(left_max, pts[perm[i]][a]);
    node.axis = a;
    node.lo = left_max;
    node.hi = pts[perm[mid]][a];
    node.right = id + 1 + nodeCount(mid - begin, leaf);
    const std::uint32_t right = node.right;  // `node` may not be touched once children run in parallel
    if (threads > 1) {
      std::thread helper([&] { run(id + 1, begin, mid, 1); });
      run(right, mid, end, 1);
      helper.join();
    } else {
      run(id + 1, begin, mid, 1);
      run(right, mid, end, 1);
    }
  }
};

KdTree::KdTree(std::span<const Eigen::Vector4d> points, const KdTreeOptions& options) {
  if (points.size() >= std::numeric_limits<std::uint32_t>::max() - 1) {
    throw std::length_error("KdTree: too many points");
  }
  if (points.empty()) return;
  const std::size_t leaf = std::max<std::size_t>(options.leaf_size, 1);
  Eigen::Vector3d lo = points[0].head<3>(), hi = lo;
  for (const auto& p : points) {
    lo = lo.cwiseMin(p.head<3>());
    hi = hi.cwiseMax(p.head<3>());
  }
  center_ = 0.5 * (lo + hi);
  std::vector<Eigen::Vector4f> local_pts(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    local_pts[i] << (points[i].head<3>() - center_).cast<float>(), 0.0F;
  }
  box_min_ = (lo - center_).cast<float>();
  box_max_ = (hi - center_).cast<float>();
  index_.resize(points.size());
  for (std::size_t i = 0; i < index_.size(); ++i) index_[i] = static_cast<std::uint32_t>(i);
  nodes_.resize(nodeCount(points.size(), leaf));
  Build build{local_pts, index_, nodes_, leaf};
  build.run(0, 0, static_cast<std::uint32_t>(points.size()), options.num_threads);
  points_.resize(points.size());
  where_.resize(points.size());
  for (std::size_t i = 0; i < index_.size(); ++i) {
    points_[i] = local_pts[index_[i]];
    where_[index_[i]] = static_cast<std::uint32_t>(i);
  }
}

void KdTree::useLeafOrderIndices() {
  std::vector<std::uint32_t>().swap(index_);
  std::vector<std::uint32_t>().swap(where_);
}

Eigen::Vector4f KdTree::local(const Eigen::Vector4d& q) const {
  Eigen::Vector4f out;
  out << (q.head<3>() - center_).cast<float>(), 0.0F;
  return out;
}

float KdTree::initialBound(const Eigen::Vector4f& q, float* off) const {
  float rd = 0.0F;
  for (int a = 0; a < 3; ++a) {
    float d = 0.0F;
    if (q[a] < box_min_[a]) d = box_min_[a] - q[a];
    if (q[a] > box_max_[a]) d = q[a] - box_max_[a];
    off[a] = d * d;
    rd += off[a];
  }
  return rd;
}

// Depth-first, nearest child first, without recursion. Each pending far child carries the squared
// distance from q to its cell along every axis (off) and their sum (rd): a lower bound on the distance
// to any point below it (incremental distance, Arya & Mount), so it is skipped once the bound is beaten.
// `Set` keeps the candidates: bound() is the distance a point must beat, scanLeaf() offers a leaf's points.
template <class Set>
void KdTree::search(const Eigen::Vector4f& q, Set& set) const {
  struct Pending {
    std::uint32_t node;
    float rd;
    float off[3];
  };
  Pending stack[64];  // depth of a median-split tree over < 2^32 points is < 33
  int top = 0;
  stack[0].node = 0;
  stack[0].rd = initialBound(q, stack[0].off);
  ++top;
  while (top > 0) {
    const Pending cur = stack[--top];
    if (!(cur.rd < set.bound())) continue;
    std::uint32_t id = cur.node;
    float rd = cur.rd;
    float off[3] = {cur.off[0], cur.off[1], cur.off[2]};
    for (;;) {
      const Node& node = nodes_[id];
      if (node.axis == kLeaf) {
        set.scanLeaf(points_.data(), node.begin, node.end, q);
        break;
      }
      const std::uint32_t a = node.axis;
      const float diff_lo = q[a] - node.lo;
      const float diff_hi = q[a] - node.hi;
      std::uint32_t near = id + 1, far = node.right;
      float cut = diff_hi;
      if (diff_lo + diff_hi >= 0.0F) {
        near = node.right;
        far = id + 1;
        cut = diff_lo;
      }
      const float cut2 = cut * cut;
      const float far_rd = rd - off[a] + cut2;
      if (far_rd < set.bound()) {
        Pending& p = stack[top++];
        p.node = far;
        p.rd = far_rd;
        p.off[0] = off[0];
        p.off[1] = off[1];
        p.off[2] = off[2];
        p.off[a] = cut2;
      }
      id = near;
    }
  }
}

namespace {
struct NearestSet {
  std::uint32_t index;
  float d;
  float prune;  // 1, or 1 / (1 + ε)² for a (1 + ε)-approximate answer: cells must be that much closer
  [[nodiscard]] float bound() const { return d * prune; }
  // Selects, not a branch per point: whether a leaf's point beats the best so far is a coin flip for the
  // branch predictor (callgrind: a sixth fewer mispredicted branches in a scan-to-map GICP alignment).
  void scanLeaf(const Eigen::Vector4f* points, std::uint32_t begin, std::uint32_t end, const Eigen::Vector4f& q) {
    float best = d;
    std::uint32_t at = index;
    for (std::uint32_t i = begin; i < end; ++i) {
      const float dist = (points[i] - q).squaredNorm();
      const bool closer = dist < best;
      best = closer ? dist : best;
      at = closer ? i : at;
    }
    d = best;
    index = at;
  }
};
}  // namespace

bool KdTree::nearest(const Eigen::Vector4d& q, double max_sq_distance, Neighbor* out, std::uint32_t hint,
                     float relative_error) const {
  if (points_.empty()) return false;
  const Eigen::Vector4f ql = local(q);
  Neighbor best{std::numeric_limits<std::uint32_t>::max(), toFloat(max_sq_distance)};
  if (hint < points_.size()) {
    const std::uint32_t h = leafPosition(hint);
    const float d = (points_[h] - ql).squaredNorm();
    if (d < best.sq_distance) best = {h, d};
  }
  const float scale = 1.0F + std::max(relative_error, 0.0F);
  NearestSet set{best.index, best.sq_distance, 1.0F / (scale * scale)};
  search(ql, set);
  if (set.index == std::numeric_limits<std::uint32_t>::max()) return false;
  *out = {originalIndex(set.index), set.d};
  return true;
}

namespace {
// The k best so far, sorted, in the caller's array. kSeeded: the set started from hints, which the tree
// walk will meet again and must not add twice.
template <bool kSeeded>
struct KnnSet {
  detail::TopK top;

  [[nodiscard]] float bound() const { return top.worst; }
  void scanLeaf(const Eigen::Vector4f* points, std::uint32_t begin, std::uint32_t end, const Eigen::Vector4f& q) {
    for (std::uint32_t i = begin; i < end; ++i) offer(i, (points[i] - q).squaredNorm());
  }
  void offer(std::uint32_t i, float d) {
    if (!(d < top.worst)) return;
    if constexpr (kSeeded) {
      for (std::size_t c = 0; c < top.count; ++c) {
        if (top.out[c].index == i) return;
      }
    }
    top.offer(i, d);
  }
};
}  // namespace

std::size_t KdTree::knn(const Eigen::Vector4d& q, std::size_t k, Neighbor* out, double max_sq_distance,
                        std::span<const std::uint32_t> hints) const {
  if (points_.empty() || k == 0) return 0;
  const Eigen::Vector4f ql = local(q);
  std::size_t count = 0;
  if (hints.empty()) {
    KnnSet<false> set{{out, k, 0, toFloat(max_sq_distance)}};
    search(ql, set);
    count = set.top.count;
  } else {
    KnnSet<true> set{{out, k, 0, toFloat(max_sq_distance)}};
    for (const std::uint32_t h : hints) {
      if (h < points_.size()) set.offer(leafPosition(h), (points_[leafPosition(h)] - ql).squaredNorm());
    }
    search(ql, set);
    count = set.top.count;
  }
  if (!index_.empty())
    for (std::size_t i = 0; i < count; ++i) out[i].index = index_[out[i].index];
  return count;
}

}  // namespace rigcal::registration
