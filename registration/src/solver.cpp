#include "solver.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "iterate_cycle.hpp"

namespace rigcal::registration::detail {

namespace {
std::string format(const char* fmt, double a, double b = 0.0, double c = 0.0) {
  char buf[256];
  std::snprintf(buf, sizeof buf, fmt, a, b, c);
  return buf;
}

// The step is judged in the source frame, so a small rotation far from the target origin is small.
bool isConverged(const Pose& step, const SolverParams& params) {
  return step.translation().norm() < params.transformation_epsilon && rotationAngle(step) < params.rotation_epsilon;
}

Status stopStatus(const Deadline& deadline) {
  return deadline.check() == StopReason::kCancelled ? Status::kCancelled : Status::kTimeout;
}
}  // namespace

SolveOutcome solve(Objective& objective, const Pose& guess, const SolverParams& params, const Deadline& deadline) {
  SolveOutcome out;
  out.T = guess;
  out.T_linearized = guess;
  double lambda = params.initial_lambda;
  IterateCycle cycle;
  for (int it = 0; it < params.max_iterations; ++it) {
    std::optional<LinearSystem> sys = objective.linearize(out.T, deadline);
    if (!sys) {
      out.status = stopStatus(deadline);
      return out;
    }
    if (!sys->H.allFinite() || !sys->b.allFinite() || !std::isfinite(sys->cost)) {
      // Only non-finite attributes can get here (positions are checked up front); never call that converged.
      out.status = Status::kInvalidInput;
      out.reason = format("non-finite linear system at iteration %.0f (non-finite normals, covariances or NDT cells?)",
                          it + 1.0);
      return out;
    }
    out.linearized = true;
    out.T_linearized = out.T;
    out.last = *sys;
    if (sys->inliers < params.min_correspondences) {
      out.status = Status::kTooFewCorrespondences;
      return out;
    }
    if (cycle.closes(out.T, sys->cost, params)) {  // the matches take turns: more steps only go round
      out.T = cycle.best();
      out.converged = true;
      out.status = Status::kConverged;
      return out;
    }
    // Marquardt damping on the diagonal, with a floor so directions the data leaves free (a plane's
    // tangents in point-to-plane) get a zero step instead of a singular solve.
    Vector6d diag = sys->H.diagonal().cwiseAbs();
    diag = diag.cwiseMax(1e-9 * std::max(diag.maxCoeff(), 1e-30));
    // Each rejected try damps more and halves the trust radius, so steps shrink geometrically until
    // the cost drops (a descent direction always gets there) or they are negligibly small.
    bool accepted = false;
    bool final_step = false;  // small enough to stop at once if accepted
    Vector6d delta = Vector6d::Zero();
    Pose T_new = out.T;
    double radius = objective.maxStep();
    for (int attempt = 0; attempt < 20 && !accepted; ++attempt) {
      Matrix6d A = sys->H;
      A.diagonal() += lambda * diag;
      delta = A.ldlt().solve(-sys->b);
      const double norm = delta.norm();
      if (norm > radius) delta *= radius / norm;
      // Not a descent direction for the local model (an indefinite Hessian) or no step at all: damp more.
      if (!delta.allFinite() || !(sys->b.dot(delta) < 0.0)) {
        lambda *= 10.0;
        continue;
      }
      T_new = expSE3(delta) * out.T;  // left perturbation, see kernels.hpp
      final_step = isConverged(out.T.inverse() * T_new, params);
      const std::optional<double> c = objective.cost(T_new, deadline, !final_step);
      if (!c) {
        out.status = stopStatus(deadline);
        out.T = out.T_linearized;
        return out;
      }
      if (*c <= sys->cost) {
        accepted = true;
        lambda = std::max(lambda * 0.1, 1e-12);
      } else {
        lambda *= 10.0;
        radius = 0.5 * std::min(radius, delta.norm());
      }
    }
    out.iterations = it + 1;
    if (!accepted) {  // no step lowers the cost any more: this is the minimum for these matches
      out.converged = true;
      out.status = Status::kConverged;
      return out;
    }
    out.T = T_new;
    if (final_step) {
      out.converged = true;
      out.status = Status::kConverged;
      return out;
    }
  }
  out.status = Status::kMaxIterations;
  return out;
}

// The first iterations move the source furthest, so each pays a fresh nearest-neighbour search for every
// point, while a uniform subsample of a few thousand points already finds the same basin: it takes those
// steps for a fraction of the searches, and all points then start next to their optimum (searches short
// or skipped). Bench scan-to-map GICP, 18.7k points (stride 4): 45 → 25 ms; a 105k-point VLS-128 scan
// against its 141k-point map (stride 16): 3x faster for GICP and ICP alike, from 0.3–1 m and 3–15° off,
// and every start that converged with all points alone still converged. The two stages may settle in
// different local minima of the piecewise matching cost, within the convergence tolerance of each other.
constexpr std::size_t kCoarseMinPoints = 4096;  // what the subsample keeps at least
constexpr std::size_t kMaxCoarseStride = 256;
constexpr double kCoarseTranslationEpsilon = 1e-3;  // m
constexpr double kCoarseRotationEpsilon = 1e-3;     // rad

SolveOutcome solveCoarseToFine(Objective& objective, std::size_t source_points, const Pose& guess,
                               const SolverParams& params, const Deadline& deadline) {
  std::size_t stride = 1;
  while (2 * stride <= kMaxCoarseStride && source_points / (2 * stride) >= kCoarseMinPoints) stride *= 2;
  SolverParams coarse_params = params;
  coarse_params.max_iterations = params.max_iterations / 2;  // the fine stage always gets the rest
  // Close enough for the fine stage: tighter tolerances only make the subsample grind on matches it
  // cannot resolve (the ensemble's ultra-fine ICP, 1e-5 m / 1e-6 rad: 100 coarse iterations, not converged).
  coarse_params.transformation_epsilon = std::max(params.transformation_epsilon, kCoarseTranslationEpsilon);
  coarse_params.rotation_epsilon = std::max(params.rotation_epsilon, kCoarseRotationEpsilon);
  if (!params.coarse_to_fine || stride == 1 || coarse_params.max_iterations == 0 || !objective.useEvery(stride)) {
    return solve(objective, guess, params, deadline);
  }
  const SolveOutcome coarse = solve(objective, guess, coarse_params, deadline);
  objective.useEvery(1);
  if (coarse.status == Status::kTimeout || coarse.status == Status::kCancelled) {
    SolveOutcome out = coarse;
    out.linearized = false;  // its metrics cover the subsample only: report its pose, unevaluated
    return out;
  }
  // Too few matches or a bad system in the subsample: all points decide from the guess, as without it.
  const bool moved = coarse.status == Status::kConverged || coarse.status == Status::kMaxIterations;
  SolverParams fine_params = params;
  fine_params.max_iterations = params.max_iterations - (moved ? coarse.iterations : 0);
  SolveOutcome fine = solve(objective, moved ? coarse.T : guess, fine_params, deadline);
  if (moved) fine.iterations += coarse.iterations;
  return fine;
}

std::string validateInputs(std::span<const SourceTarget> pairs, const Pose& guess, const SolverParams& params,
                           double max_distance) {
  if (pairs.empty()) return "no source/target pair given";
  if (!guess.matrix().allFinite()) return "initial guess is not finite";
  if (!(std::isfinite(max_distance) && max_distance > 0.0)) {
    return format("max_correspondence_distance must be finite and > 0 (got %g)", max_distance);
  }
  if (params.max_iterations < 0 || params.num_threads < 1) return "max_iterations < 0 or num_threads < 1";
  std::size_t source_points = 0;
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    const auto& [source, target] = pairs[i];
    if (source == nullptr || target == nullptr) return "null source or target";
    for (const auto& p : source->points) {
      if (!p.allFinite() || p.w() != 1.0) return "source contains non-finite points (build it with fromScan/fromTable)";
    }
    if (target->empty()) return pairs.size() == 1 ? "target is empty" : "a target is empty";
    source_points += source->size();
  }
  if (source_points == 0) return "source is empty";
  if (source_points < params.min_correspondences) {
    return format("source has %.0f points, fewer than min_correspondences (%.0f)",
                  static_cast<double>(source_points), static_cast<double>(params.min_correspondences));
  }
  return {};
}

RegistrationResult invalid(const Pose& guess, std::string reason, double max_distance) {
  RegistrationResult r;
  r.T_target_source = guess.matrix().allFinite() ? guess : Pose::Identity();
  r.status = Status::kInvalidInput;
  r.reason = std::move(reason);
  const double d = std::isfinite(max_distance) && max_distance > 0.0 ? max_distance : 0.0;
  r.rmse = d;
  r.fitness = d * d;
  return r;
}

RegistrationResult finish(const SolveOutcome& outcome, Objective& objective,
                          std::span<const SourceTarget> pairs, double max_distance, const SolverParams& params,
                          const Deadline& deadline, std::string_view method) {
  RegistrationResult r;
  r.iterations = outcome.iterations;
  r.converged = outcome.converged;
  r.status = outcome.status;
  r.T_target_source = outcome.T;
  std::size_t points = 0;
  for (const auto& p : pairs) points += p.source->size();

  std::optional<Evaluation> eval;
  if (!deadline.expired()) {
    if (const std::optional<LinearSystem> m = objective.measure(outcome.T, deadline)) {
      Evaluation e;
      e.points = points;
      e.inliers = m->inliers;
      finishEvaluation(e, m->sum_sq_distance, max_distance);
      eval = e;
    } else if (!deadline.expired()) {
      eval = evaluatePairs(pairs, outcome.T, max_distance, params.num_threads, &deadline);
    }
  }
  bool evaluated = eval.has_value();
  if (!eval) {
    // Out of time: report the last pose whose matches were fully computed, with those metrics.
    Evaluation e;
    e.points = points;
    double sum_sq = 0.0;
    if (outcome.linearized && objective.reportsNeighborMetrics()) {
      r.T_target_source = outcome.T_linearized;
      e.inliers = outcome.last.inliers;
      sum_sq = outcome.last.sum_sq_distance;
      evaluated = true;
    } else if (outcome.linearized) {
      r.T_target_source = outcome.T_linearized;
    }
    finishEvaluation(e, sum_sq, max_distance);
    eval = e;
  }
  r.rmse = eval->rmse;
  r.inlier_ratio = eval->inlier_ratio;
  r.fitness = eval->fitness;
  r.inliers = eval->inliers;

  const std::string name(method);
  const double its = static_cast<double>(outcome.iterations);
  switch (outcome.status) {
    case Status::kConverged:
    case Status::kMaxIterations:
      if (params.check_degeneracy && !deadline.expired()) {
        r.conditioning = conditioning(pairs, r.T_target_source, max_distance);
        if (r.conditioning < params.degeneracy_threshold) {
          r.status = Status::kDegenerate;
          r.reason = name + format(": degenerate geometry, conditioning %.2g < %.2g (a plane, a corridor?); "
                                   "the pose is unreliable along the free directions",
                                   r.conditioning, params.degeneracy_threshold);
          break;
        }
      }
      r.reason = outcome.status == Status::kConverged
                     ? name + format(": converged after %.0f iterations", its)
                     : name + format(": reached max_iterations (%.0f) before converging", its);
      break;
    case Status::kTimeout:
    case Status::kCancelled:
      r.reason = name + (outcome.status == Status::kTimeout ? ": deadline reached" : ": cancelled") +
                 format(" after %.0f iterations; returning the best evaluated pose", its) +
                 (outcome.linearized ? "" : " (the initial guess)") + (evaluated ? "" : ", metrics not evaluated");
      break;
    case Status::kTooFewCorrespondences:
      r.reason = name + format(": only %.0f correspondences within %g m (need %.0f); no overlap or guess too far off",
                               static_cast<double>(outcome.last.inliers), max_distance,
                               static_cast<double>(params.min_correspondences));
      break;
    default:
      r.reason = name + ": " + outcome.reason;
      break;
  }
  if (!r.T_target_source.matrix().allFinite()) {  // cannot happen with finite inputs; never hand out NaN
    r.T_target_source = Pose::Identity();
    r.status = Status::kInvalidInput;
    r.reason = name + ": numerical failure (non-finite pose)";
  }
  return r;
}

std::vector<PairChunk> makeChunks(std::span<const SourceTarget> pairs, std::size_t chunk) {
  std::vector<PairChunk> chunks;
  std::size_t offset = 0;
  for (std::size_t p = 0; p < pairs.size(); ++p) {
    const std::size_t n = pairs[p].source->size();
    for (std::size_t b = 0; b < n; b += chunk) chunks.push_back({p, b, std::min(n, b + chunk), offset + b});
    offset += n;
  }
  return chunks;
}

}  // namespace rigcal::registration::detail
