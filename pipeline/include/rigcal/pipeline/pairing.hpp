#pragma once
// Pairs a mapping-lidar keyframe with the calibration-lidar scan nearest in time, interpolates the
// mapping pose at that scan's stamp, and measures how trustworthy the interpolation is.
#include <optional>
#include <string>
#include <vector>

#include "rigcal/config/parameters.hpp"
#include "rigcal/pipeline/mapping_frame.hpp"

namespace rigcal::pipeline {

struct InterpolationStats {
  double time_s = 0;      // |t_scan − t_keyframe|
  double distance_m = 0;  // path travelled in that time
  double angle_deg = 0;   // rotation between the keyframe pose and the interpolated pose
  double speed = 0;       // m/s over the three frames around the scan
  double accel = 0;       // m/s² over the same frames
};

struct Pairing {
  std::size_t keyframe_frame = 0;  // index into the tracker's frames()
  std::uint64_t scan_sequence = 0;
  TimeNs scan_stamp_ns = 0;
  Pose T_map_mapping_at_scan = Pose::Identity();  // interpolated mapping-lidar pose at the scan stamp
  InterpolationStats stats;
  bool stopped = false;
  bool standard_ok = false;
  bool straight_ok = false;
  bool accepted = false;
  std::string rejection;  // empty when accepted
};

/// Interpolates frames[keyframe_frame]'s neighbourhood at `scan_stamp_ns`. nullopt while the frames
/// after the scan stamp do not exist yet (call again later) or when none bracket it.
std::optional<Pairing> pairKeyframe(const std::vector<MappingFrame>& frames, std::size_t keyframe_frame,
                                    std::uint64_t scan_sequence, TimeNs scan_stamp_ns,
                                    const config::Parameters& params);

}  // namespace rigcal::pipeline
