#pragma once
// Re-deskews a calibration lidar's raw sweep through the mapping trajectory and an extrinsic: the pipeline
// deskews with the initial guess; once the extrinsic is calibrated, the sweep is deskewed again with it
// before the final registration (a 5° error in the guess bends a sweep taken while turning).
#include <vector>

#include "rigcal/core/pose.hpp"
#include "rigcal/core/scan.hpp"
#include "rigcal/pipeline/mapping_frame.hpp"

namespace rigcal::calib {

/// T_map_mapping at time t by pipeline::poseOnTrajectory (the rule the pipeline's deskew stage uses too:
/// lerp/slerp, the nearest two extrapolated outside). Throws std::invalid_argument for fewer than two poses
/// or unsorted stamps.
Pose mappingPoseAt(const std::vector<pipeline::MappingFrame>& trajectory, TimeNs t);

/// `raw` (calibration-lidar frame, each point at its own time) expressed in the calibration-lidar frame
/// at raw.stamp_ns, with the calibration lidar moving as T_map_mapping(t)·T_mapping_calib.
Scan deskewThroughMapping(const Scan& raw, const std::vector<pipeline::MappingFrame>& trajectory,
                          const Pose& T_mapping_calib);

}  // namespace rigcal::calib
