#include "rigcal/registration/evaluator.hpp"

#include <atomic>
#include <cmath>
#include <stdexcept>
#include <string>

#include "rigcal/registration/parallel.hpp"
#include "solver.hpp"

namespace rigcal::registration {

void finishEvaluation(Evaluation& e, double sum_sq_distance, double max_distance) {
  const double max_sq = max_distance * max_distance;
  e.mean_sq_distance = e.inliers > 0 ? sum_sq_distance / static_cast<double>(e.inliers) : max_sq;
  e.rmse = std::sqrt(e.mean_sq_distance);
  e.inlier_ratio = e.points > 0 ? static_cast<double>(e.inliers) / static_cast<double>(e.points) : 0.0;
  e.fitness = e.points > 0 ? (sum_sq_distance + static_cast<double>(e.points - e.inliers) * max_sq) /
                                 static_cast<double>(e.points)
                           : max_sq;
}

namespace detail {

namespace {
struct Partial {
  std::size_t inliers = 0;
  double sum_sq = 0.0;
  Partial& operator+=(const Partial& o) {
    inliers += o.inliers;
    sum_sq += o.sum_sq;
    return *this;
  }
};
}  // namespace

std::optional<Evaluation> evaluatePairs(std::span<const SourceTarget> pairs, const Pose& T, double max_distance,
                                        int num_threads, const Deadline* deadline) {
  const std::vector<PairChunk> chunks = makeChunks(pairs);
  const Eigen::Matrix4d M = T.matrix();
  const double max_sq = max_distance * max_distance;
  std::atomic<bool> stopped{false};
  const Partial total = parallelReduce(chunks.size(), num_threads, Partial{}, [&](std::size_t t) {
    Partial part;
    if (deadline != nullptr && (stopped.load(std::memory_order_relaxed) || deadline->expired())) {
      stopped.store(true, std::memory_order_relaxed);
      return part;
    }
    const PairChunk& c = chunks[t];
    const PointCloud& source = *pairs[c.pair].source;
    const Target& target = *pairs[c.pair].target;
    for (std::size_t i = c.begin; i < c.end; ++i) {
      const Eigen::Vector4d q = M * source.points[i];
      Neighbor nb;
      if (!target.tree().nearest(q, max_sq, &nb)) continue;
      const double d2 = (target.cloud().points[nb.index] - q).squaredNorm();
      if (d2 > max_sq) continue;  // the tree works in float; the metric is exact
      ++part.inliers;
      part.sum_sq += d2;
    }
    return part;
  });
  if (stopped.load()) return std::nullopt;
  Evaluation e;
  for (const auto& p : pairs) e.points += p.source->size();
  e.inliers = total.inliers;
  finishEvaluation(e, total.sum_sq, max_distance);
  return e;
}

}  // namespace detail

Evaluation evaluate(std::span<const SourceTarget> pairs, const Pose& T_target_source, double max_distance,
                    int num_threads) {
  if (!(std::isfinite(max_distance) && max_distance > 0.0)) {
    throw std::invalid_argument("evaluate: max_distance must be finite and > 0, got " + std::to_string(max_distance));
  }
  for (const auto& p : pairs) {
    if (p.source == nullptr || p.target == nullptr) throw std::invalid_argument("evaluate: null source or target");
  }
  return *detail::evaluatePairs(pairs, T_target_source, max_distance, num_threads, nullptr);
}

Evaluation evaluate(const Target& target, const PointCloud& source, const Pose& T_target_source,
                    double max_distance, int num_threads) {
  const SourceTarget pair{&source, &target};
  return evaluate(std::span<const SourceTarget>(&pair, 1), T_target_source, max_distance, num_threads);
}

}  // namespace rigcal::registration
