#include "rigcal/registration/registration_result.hpp"

namespace rigcal::registration {

std::string_view toString(Status status) {
  switch (status) {
    case Status::kConverged:
      return "converged";
    case Status::kMaxIterations:
      return "max_iterations";
    case Status::kTimeout:
      return "timeout";
    case Status::kCancelled:
      return "cancelled";
    case Status::kDegenerate:
      return "degenerate";
    case Status::kTooFewCorrespondences:
      return "too_few_correspondences";
    case Status::kInvalidInput:
      return "invalid_input";
  }
  return "unknown";
}

}  // namespace rigcal::registration
