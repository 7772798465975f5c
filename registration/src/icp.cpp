#include "rigcal/registration/icp.hpp"

#include "correspondence_objective.hpp"
#include "rigcal/registration/batched_icp.hpp"

namespace rigcal::registration {

RegistrationResult alignBatchedIcp(std::span<const SourceTarget> pairs, const Pose& guess,
                                   const BatchedIcpParams& params, const Deadline& deadline) {
  const char* name = params.method == IcpMethod::kPointToPlane ? "point-to-plane ICP" : "point-to-point ICP";
  std::string bad = detail::validateInputs(pairs, guess, params, params.max_correspondence_distance);
  if (bad.empty() && params.method == IcpMethod::kPointToPlane) {
    for (const auto& p : pairs) {
      if (!p.target->hasNormals()) bad = "target has no normals (build it with normals_and_covariances)";
    }
  }
  if (!bad.empty()) return detail::invalid(guess, std::string(name) + ": " + bad, params.max_correspondence_distance);
  detail::CorrespondenceObjective objective(
      pairs, params.method == IcpMethod::kPointToPlane ? detail::Residual::kPointToPlane : detail::Residual::kPointToPoint,
      params.max_correspondence_distance, params.num_threads);
  std::size_t source_points = 0;
  for (const auto& p : pairs) source_points += p.source->size();
  const detail::SolveOutcome outcome = detail::solveCoarseToFine(objective, source_points, guess, params, deadline);
  return detail::finish(outcome, objective, pairs, params.max_correspondence_distance, params, deadline, name);
}

RegistrationResult alignIcp(const Target& target, const PointCloud& source, const Pose& guess,
                            const IcpParams& params, const Deadline& deadline) {
  const SourceTarget pair{&source, &target};
  return alignBatchedIcp(std::span<const SourceTarget>(&pair, 1), guess, params, deadline);
}

}  // namespace rigcal::registration
