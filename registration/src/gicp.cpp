#include "rigcal/registration/gicp.hpp"

#include <optional>

#include "correspondence_objective.hpp"

namespace rigcal::registration {

RegistrationResult alignGicp(const Target& target, const PointCloud& source, const Pose& guess,
                             const GicpParams& params, const Deadline& deadline) {
  constexpr const char* kName = "GICP";
  SourceTarget pair{&source, &target};
  std::string bad = detail::validateInputs({&pair, 1}, guess, params, params.max_correspondence_distance);
  if (bad.empty() && !target.hasCovariances()) {
    bad = "target has no covariances (build it with normals_and_covariances)";
  }
  if (bad.empty() && source.hasCovariances()) {
    for (const auto& c : source.covariances) {
      if (!c.allFinite()) {
        bad = "source covariances are not finite (re-estimate them with estimateCovariances)";
        break;
      }
    }
  }
  if (!bad.empty()) return detail::invalid(guess, std::string(kName) + ": " + bad, params.max_correspondence_distance);
  std::optional<PointCloud> with_covariances;
  if (!source.hasCovariances()) {
    with_covariances = source;
    CovarianceOptions options = params.source_covariance;
    options.num_threads = params.num_threads;
    estimateCovariances(*with_covariances, options);
    pair.source = &*with_covariances;
  }
  const std::span<const SourceTarget> pairs(&pair, 1);
  detail::CorrespondenceObjective objective(pairs, detail::Residual::kGicp, params.max_correspondence_distance,
                                            params.num_threads);
  const detail::SolveOutcome outcome =
      detail::solveCoarseToFine(objective, pair.source->size(), guess, params, deadline);
  return detail::finish(outcome, objective, pairs, params.max_correspondence_distance, params, deadline, kName);
}

}  // namespace rigcal::registration
