#pragma once
// One rigid transform for N (source_i, target_i) pairs at once: minimises Σ_i Σ_j ‖T·p_ij − q_ij‖²
// (or the point-to-plane form) over all pairs, e.g. every selected calibration frame against its own
// dense map, all expressed in the mapping lidar's frame, solving for T_mapping_calib.
#include <span>

#include "rigcal/core/pose.hpp"
#include "rigcal/registration/deadline.hpp"
#include "rigcal/registration/icp.hpp"
#include "rigcal/registration/registration_result.hpp"
#include "rigcal/registration/target.hpp"

namespace rigcal::registration {

using BatchedIcpParams = IcpParams;

/// Metrics in the result are over all pairs' points together. A pair whose source is empty is allowed;
/// an empty target, a null pointer or no pairs at all is invalid input.
RegistrationResult alignBatchedIcp(std::span<const SourceTarget> pairs, const Pose& guess,
                                   const BatchedIcpParams& params = {}, const Deadline& deadline = {});

}  // namespace rigcal::registration
