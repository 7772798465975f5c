#pragma once
// The schema of `parameters:`: each name, where it lives in Parameters, and what values it allows.
#include <string>
#include <variant>
#include <vector>

#include "rigcal/config/parameters.hpp"

namespace rigcal::config::detail {

struct ParameterSpec {
  const char* name;
  std::variant<double Parameters::*, int Parameters::*, bool Parameters::*, std::string Parameters::*>
      member;
  double min = 0.0;  // numeric parameters: inclusive range
  double max = 0.0;
  std::vector<std::string> choices;  // string parameters: allowed values
};

const std::vector<ParameterSpec>& parameterSpecs();

/// Upstream parameter names that rigcal accepts but does not use (cameras, object detections, ROS, and
/// upstream tuning rigcal has no counterpart for), each with a warning.
const std::vector<std::string>& ignoredUpstreamParameters();

}  // namespace rigcal::config::detail
