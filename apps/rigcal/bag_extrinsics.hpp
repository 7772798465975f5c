#pragma once
// `initial_extrinsics: from_bag` (for the whole rig or per sensor): each such sensor's initial extrinsic
// is its frame in the bag's tf tree (/tf_static, then /tf) composed up to the rig's base frame. A
// sensor's frame is its source.frame, else the frame_id of its topic's first message.
#include "rigcal/config/rig_config.hpp"
#include "rigcal/pipeline/pipeline.hpp"

namespace rigcal::app {

/// Replaces the placeholders of rig.extrinsics_from_bag and prints, per sensor, the frames used (stderr).
/// Throws CommandFailed: kExitUsage when the input is not a bag; kExitInput (one line, listing the tree's
/// frames) when a frame is missing or not connected to the base frame.
void applyExtrinsicsFromBag(config::RigConfig& rig, const pipeline::PipelineOptions& options);

}  // namespace rigcal::app
