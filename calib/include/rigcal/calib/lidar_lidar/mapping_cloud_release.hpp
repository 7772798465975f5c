#pragma once
// When a calibration may let go of a dataset's mapping clouds (issue #18): a cloud is only read to build
// the augmented targets of the frames whose window names it, and the targets are built in frame order.
// Once every frame that names it has had its turn, the cloud is dead weight for the rest of the calibration
// (the ensembles, the batched ICP, the re-deskew read the targets and the raw scans, never the clouds).
#include <cstddef>

#include "rigcal/pipeline/calibration_dataset.hpp"

namespace rigcal::calib {

/// Resets (`cloud` = nullptr; the frame and its pose stay, so windows keep their indices) every mapping
/// cloud that no frame from `first_pending` on names in its window; `first_pending` = frames.size() drops
/// them all. A pending frame with an empty window (a dataset made by hand: its target takes every cloud
/// of its keyframe range) keeps them all. Returns how many were reset.
std::size_t dropMappingCloudsDoneWith(pipeline::CalibrationDataset& dataset, std::size_t first_pending);

}  // namespace rigcal::calib
