#include "correspondence_objective.hpp"

#include <atomic>
#include <cmath>
#include <limits>
#include <utility>

#include "gicp_batch.hpp"
#include "kernels.hpp"
#include "spatial_order.hpp"
#include "rigcal/registration/parallel.hpp"

namespace rigcal::registration::detail {

// Residual r = q − t with q = T·p the transformed source point and t its matched target point.
// See kernels.hpp for the Jacobian and how each method's blocks are accumulated.

CorrespondenceObjective::CorrespondenceObjective(std::span<const SourceTarget> pairs, Residual kind,
                                                 double max_distance, int num_threads)
    : pairs_(pairs), kind_(kind), max_sq_(max_distance * max_distance), num_threads_(num_threads) {
  chunks_ = makeChunks(pairs, kChunkSize);
  std::size_t total = 0;
  for (const auto& p : pairs) total += p.source->size();
  // Every per-point array below is in each source's spatial order, and so are the chunks: a chunk's
  // queries land on neighbouring target points, which stay in cache from one query to the next.
  source_points_.reserve(total);
  std::vector<std::uint32_t> order;
  order.reserve(total);
  for (const auto& p : pairs) {
    const std::vector<std::uint32_t> o = spatialOrder(p.source->points, kOrderCell);
    for (const std::uint32_t i : o) source_points_.push_back(p.source->points[i]);
    order.insert(order.end(), o.begin(), o.end());
  }
  match_.assign(total, kNone);
  used_.assign(total, kNone);
  used_next_.assign(total, kNone);
  second_.assign(total, kNone);
  query_.assign(total, Eigen::Vector3f::Zero());
  margin_.assign(total, -1.0F);
  held_.resize(total);
  if (kind == Residual::kGicp) {
    weight_.resize(total);
    weight_next_.resize(total);
    source_cov_.reserve(total);
    std::size_t at = 0;
    for (const auto& p : pairs) {
      for (std::size_t n = 0; n < p.source->size(); ++n, ++at) {
        source_cov_.push_back(Sym3::upperOf(p.source->covariances[order[at]]));
      }
    }
    source_axis_.resize(total);
    for (std::size_t g = 0; g < total; ++g) {
      if (!rankOneFromIdentity(source_cov_[g], &source_axis_[g])) {
        source_axis_.clear();  // a general covariance somewhere: the general kernel for all
        break;
      }
    }
  }
}

bool CorrespondenceObjective::useEvery(std::size_t stride) {
  if (stride == 0 || (stride & (stride - 1)) != 0 || kChunkSize % stride != 0) return false;
  stride_ = stride;
  cached_.reset();  // a linearisation over the other subset
  return true;
}

// Every target point outside {c} ∪ N(c) is at least R_c from c, hence at least R_c − |q − c| from q. So
// when the best candidate in {c} ∪ N(c) is closer than that, it is the exact nearest point, and
// min(second best, R_c − |q − c|) bounds the runner-up: enough for the margin.
// Hops of the walk before the tree decides (callgrind: 3 → 6 saves ~1.5 %, 12 no more).
constexpr int kMaxHops = 6;

bool CorrespondenceObjective::graphSearch(const Target& target, std::uint32_t start, const Eigen::Vector4d& q,
                                          std::uint32_t* j, float* margin) const {
  // In the tree's float copy of the points (half the memory of the cloud's doubles: on a dense map the
  // walk is memory-bound). Slack for float rounding: the graph's radii are float tree distances too, and
  // coordinates far from the tree's centre round more coarsely.
  const std::span<const Eigen::Vector4f> pts = target.tree().localPoints();
  const Eigen::Vector4f ql = target.tree().toLocal(q);
  const float slack = 1e-4F + 4e-7F * ql.cwiseAbs().maxCoeff();
  const NeighborGraph& graph = target.neighborGraph();
  std::uint32_t c = start;
  for (int hop = 0; hop < kMaxHops; ++hop) {
    const float dc2 = (ql - pts[c]).squaredNorm();
    std::uint32_t best = c;
    float best2 = dc2, second2 = std::numeric_limits<float>::infinity();
    for (std::size_t r = 0; r < graph.degree; ++r) {
      const std::uint32_t k = graph.neighbor(c, r);
      const float d2 = (ql - pts[k]).squaredNorm();
      if (d2 < best2) {
        second2 = best2;
        best2 = d2;
        best = k;
      } else if (d2 < second2) {
        second2 = d2;
      }
    }
    const float limit = graph.radius[c] - std::sqrt(dc2) - slack;
    const float best_d = std::sqrt(best2);
    if (best_d < limit) {
      if (static_cast<double>(best2) > max_sq_) {
        *j = kNone;
        return true;
      }
      *j = best;
      *margin = 0.5F * (std::min(std::sqrt(second2), limit) - best_d) - slack;
      return true;
    }
    // Walk towards q and try again from there, unless that point cannot vouch for anything as close as
    // itself (q is further off the surface than its neighbour list reaches): the tree decides sooner.
    if (best == c || !(graph.radius[best] - best_d - slack > 0.0F)) return false;
    c = best;
  }
  return false;
}

bool CorrespondenceObjective::match(const Target& target, std::size_t g, const Eigen::Vector4d& q,
                                    std::uint32_t* j) {
  const Eigen::Vector3f qf = q.head<3>().cast<float>();
  const std::uint32_t last = match_[g];
  if (last != kNone && margin_[g] > 0.0F && (qf - query_[g]).squaredNorm() < margin_[g] * margin_[g]) {
    *j = last;
    return true;
  }
  query_[g] = qf;
  if (last != kNone && !target.neighborGraph().empty()) {
    std::uint32_t found = kNone;
    float margin = 0.0F;
    if (graphSearch(target, last, q, &found, &margin)) {
      match_[g] = found;
      margin_[g] = margin;
      *j = found;
      return found != kNone;
    }
  }
  if (last == kNone || !target.neighborGraph().empty()) {
    // A first search, or a walk that could not prove its answer (the point is further from the surface
    // than the graph vouches for): the point still moves too far before the next pass for a margin to
    // pay off (the runner-up costs a wider search), so the nearest alone will do, bounded by the last
    // match. The next pass walks from what is found here.
    Neighbor nb;
    second_[g] = kNone;
    margin_[g] = -1.0F;
    if (!target.tree().nearest(q, max_sq_, &nb, last, last == kNone ? kFirstSearchError : 0.0F)) {
      match_[g] = kNone;
      return false;
    }
    match_[g] = nb.index;
    *j = nb.index;
    return true;
  }
  // No graph: the nearest two, so that the margin can spare later passes the tree.
  Neighbor nb[2];
  std::uint32_t hints[2];
  std::size_t num_hints = 0;
  hints[num_hints++] = last;
  if (second_[g] != kNone) hints[num_hints++] = second_[g];
  const std::size_t found = target.tree().knn(q, 2, nb, max_sq_, {hints, num_hints});
  if (found == 0) {
    match_[g] = kNone;
    second_[g] = kNone;
    return false;
  }
  second_[g] = found == 2 ? nb[1].index : kNone;
  // With no second point within range, the range bounds the runner-up instead. 1e-4 m absorbs the
  // float rounding of the tree's distances.
  const float second = found == 2 ? std::sqrt(nb[1].sq_distance) : static_cast<float>(std::sqrt(max_sq_));
  margin_[g] = 0.5F * (second - std::sqrt(nb[0].sq_distance)) - 1e-4F;
  match_[g] = nb[0].index;
  *j = nb[0].index;
  return true;
}

void CorrespondenceObjective::hold(std::size_t g, const Target& target, std::uint32_t j) {
  Held& h = held_[g];
  if (h.index == j) return;
  h.index = j;
  h.point = target.cloud().points[j].head<3>();
  if (kind_ == Residual::kGicp) {
    const float* c = target.covarianceUpperFloat().data() + 6 * std::size_t{j};
    for (std::size_t e = 0; e < 6; ++e) h.covariance[e] = c[e];  // (std::copy calls memmove here)
  }
}

template <Residual K>
double CorrespondenceObjective::costTerm(std::size_t g, const Eigen::Vector3d& r, const Target& target,
                                         std::uint32_t j) const {
  if constexpr (K == Residual::kPointToPlane) {
    const double e = target.normal(j).dot(r);
    return e * e;
  } else if constexpr (K == Residual::kGicp) {
    (void)target, (void)j;
    return r.dot(weight_[g].times(r));
  } else {
    (void)g, (void)target, (void)j;
    return r.squaredNorm();
  }
}

template <Residual K, bool kPrevious>
CorrespondenceObjective::Pass CorrespondenceObjective::linearizeChunk(const PairChunk& chunk,
                                                                      const Eigen::Matrix4d& M) {
  const Target& target = *pairs_[chunk.pair].target;
  const Eigen::Matrix3d R = M.topLeftCorner<3, 3>();
  Pass out;
  LinearSystem& sys = out.sys;
  PointToPointSums p2p;
  GicpBatch gicp;
  for (std::size_t i = chunk.begin; i < chunk.end; i += stride_) {
    const std::size_t g = chunk.offset + (i - chunk.begin);
    const Eigen::Vector4d q4 = M * source_points_[g];
    if constexpr (kPrevious) {  // exactly costChunk's term: the acceptance test sees the same number
      const std::uint32_t previous = used_[g];
      if (previous != kNone) {
        out.previous_cost += costTerm<K>(g, q4.head<3>() - targetPoint(g, target, previous), target, previous);
      }
    }
    std::uint32_t j = kNone;
    used_next_[g] = kNone;
    if (!match(target, g, q4, &j)) continue;
    hold(g, target, j);
    const Eigen::Vector3d q = q4.head<3>();
    const Eigen::Vector3d r = q - held_[g].point;
    const double d2 = r.squaredNorm();
    if (d2 > max_sq_) continue;  // exact distance just outside the (float) search radius
    if constexpr (K == Residual::kPointToPlane) {
      const Eigen::Vector3d n = target.normal(j);
      if (n.squaredNorm() < 0.5) continue;  // no normal known there
      const double e = n.dot(r);
      Vector6d row;
      row << n, q.cross(n);
      addRow(row, e, sys.H, sys.b);
      sys.cost += e * e;
    } else if constexpr (K == Residual::kGicp) {
      const Sym3 t = Sym3::load(held_[g].covariance.data());
      if (source_axis_.empty()) {
        gicp.add(q, r, fusedCovariance(R, source_cov_[g], t), Eigen::Vector3d::Zero(), &weight_next_[g]);
      } else {  // C_s = I − v·vᵀ: R·C_s·Rᵀ = I − (R·v)(R·v)ᵀ
        const Sym3 base{t.xx + 1.0, t.xy, t.xz, t.yy + 1.0, t.yz, t.zz + 1.0};
        gicp.add(q, r, base, R * source_axis_[g], &weight_next_[g]);
      }
    } else {
      p2p.add(q);
      sys.b.head<3>() += r;
      sys.b.tail<3>() += q.cross(r);
      sys.cost += d2;
    }
    used_next_[g] = j;
    ++sys.inliers;
    sys.sum_sq_distance += d2;
  }
  if constexpr (K == Residual::kPointToPoint) p2p.finish(sys.H);
  if constexpr (K == Residual::kGicp) gicp.finish(sys);
  mirrorUpper(sys.H);
  return out;
}

template <Residual K>
double CorrespondenceObjective::costChunk(const PairChunk& chunk, const Eigen::Matrix4d& M) const {
  const Target& target = *pairs_[chunk.pair].target;
  double cost = 0.0;
  for (std::size_t i = chunk.begin; i < chunk.end; i += stride_) {
    const std::size_t g = chunk.offset + (i - chunk.begin);
    const std::uint32_t j = used_[g];  // the same matches as the linearisation: the cost is comparable
    if (j == kNone) continue;
    cost += costTerm<K>(g, (M * source_points_[g]).head<3>() - targetPoint(g, target, j), target, j);
  }
  return cost;
}

std::optional<CorrespondenceObjective::Pass> CorrespondenceObjective::pass(const Eigen::Matrix4d& M,
                                                                              const Deadline& deadline,
                                                                              bool previous_cost) {
  std::atomic<bool> stopped{false};
  Pass total = parallelReduce(chunks_.size(), num_threads_, Pass{}, [&](std::size_t t) {
    if (stopped.load(std::memory_order_relaxed) || deadline.expired()) {
      stopped.store(true, std::memory_order_relaxed);
      return Pass{};
    }
    const PairChunk& c = chunks_[t];
    switch (kind_) {
      case Residual::kPointToPlane:
        return previous_cost ? linearizeChunk<Residual::kPointToPlane, true>(c, M)
                             : linearizeChunk<Residual::kPointToPlane, false>(c, M);
      case Residual::kGicp:
        return previous_cost ? linearizeChunk<Residual::kGicp, true>(c, M) : linearizeChunk<Residual::kGicp, false>(c, M);
      case Residual::kPointToPoint:
        break;
    }
    return previous_cost ? linearizeChunk<Residual::kPointToPoint, true>(c, M)
                         : linearizeChunk<Residual::kPointToPoint, false>(c, M);
  });
  if (stopped.load()) return std::nullopt;
  return total;
}

std::optional<LinearSystem> CorrespondenceObjective::linearize(const Pose& T, const Deadline& deadline) {
  std::optional<LinearSystem> sys;
  if (cached_ && cached_at_ == T.matrix()) {
    sys = std::move(cached_);  // cost() matched and linearised here already
  } else if (std::optional<Pass> p = pass(T.matrix(), deadline, false)) {
    sys = p->sys;
  }
  cached_.reset();
  if (!sys) return std::nullopt;
  used_.swap(used_next_);  // this pass's matches and weights are what cost() compares against now
  weight_.swap(weight_next_);
  return sys;
}

std::optional<LinearSystem> CorrespondenceObjective::measure(const Pose& T, const Deadline& deadline) {
  const Eigen::Matrix4d M = T.matrix();
  std::atomic<bool> stopped{false};
  LinearSystem sys = parallelReduce(chunks_.size(), num_threads_, LinearSystem{}, [&](std::size_t t) {
    LinearSystem part;
    if (stopped.load(std::memory_order_relaxed) || deadline.expired()) {
      stopped.store(true, std::memory_order_relaxed);
      return part;
    }
    const PairChunk& chunk = chunks_[t];
    const Target& target = *pairs_[chunk.pair].target;
    for (std::size_t i = chunk.begin; i < chunk.end; i += stride_) {
      const std::size_t g = chunk.offset + (i - chunk.begin);
      const Eigen::Vector4d q = M * source_points_[g];
      std::uint32_t j = kNone;
      if (!match(target, g, q, &j)) continue;
      const double d2 = (q.head<3>() - targetPoint(g, target, j)).squaredNorm();
      if (d2 > max_sq_) continue;
      ++part.inliers;
      part.sum_sq_distance += d2;
    }
    return part;
  });
  if (stopped.load()) return std::nullopt;
  return sys;
}

std::optional<double> CorrespondenceObjective::cost(const Pose& T, const Deadline& deadline, bool then_linearize) {
  const Eigen::Matrix4d M = T.matrix();
  cached_.reset();
  if (then_linearize) {
    // The cost with the current matches comes almost free with the next pass's transform of every
    // point: one pass instead of a cost pass and then a linearisation once the step is accepted.
    std::optional<Pass> p = pass(M, deadline, true);
    if (!p) return std::nullopt;
    cached_ = p->sys;
    cached_at_ = M;
    return p->previous_cost;
  }
  std::atomic<bool> stopped{false};
  const double total = parallelReduce(chunks_.size(), num_threads_, 0.0, [&](std::size_t t) {
    if (stopped.load(std::memory_order_relaxed) || deadline.expired()) {
      stopped.store(true, std::memory_order_relaxed);
      return 0.0;
    }
    switch (kind_) {
      case Residual::kPointToPlane:
        return costChunk<Residual::kPointToPlane>(chunks_[t], M);
      case Residual::kGicp:
        return costChunk<Residual::kGicp>(chunks_[t], M);
      case Residual::kPointToPoint:
        break;
    }
    return costChunk<Residual::kPointToPoint>(chunks_[t], M);
  });
  if (stopped.load()) return std::nullopt;
  return total;
}

}  // namespace rigcal::registration::detail
