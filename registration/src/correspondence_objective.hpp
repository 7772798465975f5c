#pragma once
// Private: nearest-neighbour objectives (point-to-point, point-to-plane, GICP) over one or several
// (source, target) pairs that share one pose.
#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "kernels.hpp"
#include "solver.hpp"

namespace rigcal::registration::detail {

enum class Residual { kPointToPoint, kPointToPlane, kGicp };

class CorrespondenceObjective final : public Objective {
 public:
  /// Point-to-plane needs target normals, GICP source and target covariances (checked by the caller).
  CorrespondenceObjective(std::span<const SourceTarget> pairs, Residual kind, double max_distance, int num_threads);

  std::optional<LinearSystem> linearize(const Pose& T, const Deadline& deadline) override;
  /// With `then_linearize`, one pass also linearises at T (matching there) and keeps that for linearize(T).
  std::optional<double> cost(const Pose& T, const Deadline& deadline, bool then_linearize) override;
  /// Matches only, through the same cache: after convergence almost no point needs the tree.
  std::optional<LinearSystem> measure(const Pose& T, const Deadline& deadline) override;
  /// Every stride-th point of each source's spatial order: a uniform subsample. A power of two up to
  /// the chunk size, so that chunks stay aligned to it.
  bool useEvery(std::size_t stride) override;

 private:
  /// A linearisation's sums, and with kPrevious also the cost at the same pose with the previous
  /// linearisation's matches (what cost() would return there).
  struct Pass {
    LinearSystem sys;
    double previous_cost = 0.0;
    Pass& operator+=(const Pass& o) {
      sys += o.sys;
      previous_cost += o.previous_cost;
      return *this;
    }
  };
  /// Matches and linearises at T into the *_next_ buffers (cost() still reads the current ones).
  std::optional<Pass> pass(const Eigen::Matrix4d& M, const Deadline& deadline, bool previous_cost);
  template <Residual K, bool kPrevious>
  Pass linearizeChunk(const PairChunk& chunk, const Eigen::Matrix4d& M);
  template <Residual K>
  double costChunk(const PairChunk& chunk, const Eigen::Matrix4d& M) const;
  /// Source point g's cost term for residual r against target point j, with the current weights.
  template <Residual K>
  double costTerm(std::size_t g, const Eigen::Vector3d& r, const Target& target, std::uint32_t j) const;

  /// The nearest target point of source point g (global index) at q, reusing the last one when q has
  /// moved less than half the gap between the last nearest and second-nearest distances: then, by the
  /// triangle inequality, no other point can have overtaken it. Exact, and most late-iteration queries
  /// skip the tree entirely.
  bool match(const Target& target, std::size_t g, const Eigen::Vector4d& q, std::uint32_t* j);
  /// Exact nearest point by walking the target's NeighborGraph from `start`; false when the graph
  /// cannot prove the answer (then the tree decides). On success *j is kNone if it is beyond range.
  bool graphSearch(const Target& target, std::uint32_t start, const Eigen::Vector4d& q, std::uint32_t* j,
                   float* margin) const;

  /// The target point j for source point g: from held_ when it holds j.
  [[nodiscard]] Eigen::Vector3d targetPoint(std::size_t g, const Target& target, std::uint32_t j) const {
    return held_[g].index == j ? held_[g].point : Eigen::Vector3d(target.cloud().points[j].head<3>());
  }
  /// Makes held_[g] hold target point j.
  void hold(std::size_t g, const Target& target, std::uint32_t j);

  static constexpr std::uint32_t kNone = 0xFFFFFFFFU;
  // A first search (no match yet, the source not yet moved) may answer with a point up to 1.25x as far
  // as the nearest: it skips cells sooner, and the next pass searches exactly from what it found.
  static constexpr float kFirstSearchError = 0.25F;
  // Cube edge of the sources' spatial order (m): a few source voxels, so a run of queries stays local.
  static constexpr double kOrderCell = 0.5;
  static constexpr std::size_t kChunkSize = 512;  // source points per parallel task
  std::span<const SourceTarget> pairs_;
  Residual kind_;
  double max_sq_;
  int num_threads_;
  std::size_t stride_ = 1;  // see useEvery()
  std::vector<PairChunk> chunks_;           // over positions in the spatial order (not source indices)
  std::vector<Eigen::Vector4d> source_points_;  // every source's points in spatial order, concatenated
  std::vector<std::uint32_t> match_;    // per source point (concatenated): target index or kNone
  std::vector<std::uint32_t> used_;     // the match if the last linearisation used it, else kNone
  std::vector<std::uint32_t> used_next_;  // the same for a pass not yet accepted (swapped in by linearize)
  std::vector<std::uint32_t> second_;   // the second nearest at the last search (a search hint), or kNone
  std::vector<Eigen::Vector3f> query_;  // where the last tree search for it ran
  std::vector<float> margin_;           // how far it may move from there keeping the match (m)
  std::vector<Sym3> weight_;            // GICP: (C_t + R·C_s·Rᵀ)⁻¹ at the last linearisation
  std::vector<Sym3> weight_next_;
  std::optional<LinearSystem> cached_;  // a pass cost() ran at cached_at_, for linearize() there
  Eigen::Matrix4d cached_at_ = Eigen::Matrix4d::Zero();
  /// Copies of what a residual needs from source point g's current match, kept next to the other
  /// per-source arrays: passes stream through them in order, and only a changed match reads the target
  /// (at random, a cache miss per array on a dense map).
  struct Held {
    Eigen::Vector3d point = Eigen::Vector3d::Zero();
    std::array<float, 6> covariance{};  // GICP: the target covariance's upper triangle
    std::uint32_t index = kNone;
  };
  std::vector<Held> held_;
  std::vector<Sym3> source_cov_;        // GICP: the sources' covariances, compact, concatenated
  std::vector<Eigen::Vector3d> source_axis_;  // GICP: v with C_s = I − v·vᵀ, when every source has that form
};

}  // namespace rigcal::registration::detail
