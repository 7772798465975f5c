#pragma once
// Private: the Levenberg–Marquardt loop every registration runs, and the shared ending (metrics at the
// result pose, degeneracy check, status and reason).
#include <cstddef>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "rigcal/core/pose.hpp"
#include "rigcal/registration/deadline.hpp"
#include "rigcal/registration/evaluator.hpp"
#include "rigcal/registration/registration_result.hpp"
#include "rigcal/registration/solver_params.hpp"
#include "rigcal/registration/target.hpp"

namespace rigcal::registration::detail {

using Matrix6d = Eigen::Matrix<double, 6, 6>;

/// Gauss–Newton system in the left-perturbation tangent (ρ, ω) of T: exp(δ)·T (see kernels.hpp).
struct LinearSystem {
  Matrix6d H = Matrix6d::Zero();
  Vector6d b = Vector6d::Zero();
  double cost = 0.0;
  std::size_t inliers = 0;        // correspondences used
  double sum_sq_distance = 0.0;   // their squared Euclidean distances (m²)

  LinearSystem& operator+=(const LinearSystem& o) {
    H += o.H;
    b += o.b;
    cost += o.cost;
    inliers += o.inliers;
    sum_sq_distance += o.sum_sq_distance;
    return *this;
  }
};

class Objective {
 public:
  virtual ~Objective() = default;
  /// Matches and linearises at T; nullopt when the deadline stopped it part-way.
  virtual std::optional<LinearSystem> linearize(const Pose& T, const Deadline& deadline) = 0;
  /// The cost at T with the matches of the last linearize(); nullopt on deadline. `then_linearize`: the
  /// solver will call linearize(T) next if this cost is accepted, so an objective may do both in one pass
  /// and keep the linearisation for then (false for a converging last step, where nothing follows).
  virtual std::optional<double> cost(const Pose& T, const Deadline& deadline, bool then_linearize) = 0;
  /// True when linearize()'s inliers / sum_sq_distance are nearest-neighbour metrics within the
  /// method's max distance, so they can stand in for an evaluation.
  [[nodiscard]] virtual bool reportsNeighborMetrics() const { return true; }
  /// Nearest-neighbour metrics at T (inliers and sum_sq_distance filled) if the objective can get them
  /// cheaper than a fresh evaluation; nullopt means "use evaluatePairs" (or the deadline passed).
  virtual std::optional<LinearSystem> measure(const Pose& /*T*/, const Deadline& /*deadline*/) { return std::nullopt; }
  /// Largest update norm allowed per iteration (NDT's step_size); unlimited by default.
  /// Matches and sums only every stride-th source point from now on (1: all of them); false when the
  /// objective cannot subsample (then it keeps using all).
  virtual bool useEvery(std::size_t /*stride*/) { return false; }
  [[nodiscard]] virtual double maxStep() const { return std::numeric_limits<double>::infinity(); }
};

struct SolveOutcome {
  Pose T = Pose::Identity();  // the last accepted iterate
  int iterations = 0;
  bool converged = false;
  Status status = Status::kMaxIterations;
  std::string reason;
  bool linearized = false;          // at least one linearize() completed
  Pose T_linearized = Pose::Identity();  // where the last one ran
  LinearSystem last;                // and what it found
};

SolveOutcome solve(Objective& objective, const Pose& guess, const SolverParams& params, const Deadline& deadline);

/// solve(), first on a uniform subsample of the `source_points` when there are enough of them, then on
/// all of them from where the subsample converged. Iterations count both stages.
SolveOutcome solveCoarseToFine(Objective& objective, std::size_t source_points, const Pose& guess,
                               const SolverParams& params, const Deadline& deadline);

/// Checks what every method needs; returns an empty string when fine, else the reason.
std::string validateInputs(std::span<const SourceTarget> pairs, const Pose& guess, const SolverParams& params,
                           double max_distance);

/// Metrics over the pairs at T, or nullopt if the deadline passed first.
std::optional<Evaluation> evaluatePairs(std::span<const SourceTarget> pairs, const Pose& T, double max_distance,
                                        int num_threads, const Deadline* deadline);

/// See RegistrationResult::conditioning. 0 when too few points match to say.
double conditioning(std::span<const SourceTarget> pairs, const Pose& T, double max_distance);

/// Turns a solve into the public result (metrics, degeneracy, status, reason). `method` names the
/// algorithm in the reason.
RegistrationResult finish(const SolveOutcome& outcome, Objective& objective,
                          std::span<const SourceTarget> pairs, double max_distance, const SolverParams& params,
                          const Deadline& deadline, std::string_view method);

RegistrationResult invalid(const Pose& guess, std::string reason, double max_distance);

/// Fixed-size chunks over every pair's source points, in pair order.
struct PairChunk {
  std::size_t pair = 0;
  std::size_t begin = 0, end = 0;  // source point range within the pair
  std::size_t offset = 0;          // index of `begin` in the concatenation of all sources
};
std::vector<PairChunk> makeChunks(std::span<const SourceTarget> pairs, std::size_t chunk = 512);

}  // namespace rigcal::registration::detail
