#pragma once
// An optional watcher of the pipeline (the live view): the mapper and selector threads call it with what
// they just produced. It must return at once (copy or drop, never wait): it runs on the stage threads.
// Without an observer the stages pay one null-pointer test per frame.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "rigcal/core/scan.hpp"
#include "rigcal/pipeline/mapping_frame.hpp"

namespace rigcal::pipeline {

/// One candidate pairing of a calibration lidar and that lidar's current selection, in the map frame.
struct CandidateEvent {
  int lane = 0;                                // index into the rig's calibration lidars
  Eigen::Vector3f position = Eigen::Vector3f::Zero();  // the mapping lidar at the candidate scan's stamp
  bool accepted = false;                       // passed the interpolation criteria and size filters
  std::vector<Eigen::Vector3f> selected;       // every frame the selector holds now
};

class PipelineObserver {
 public:
  virtual ~PipelineObserver() = default;
  /// Mapper thread, after every registered frame (its pose is out). `cloud`: the stored frame's cloud in
  /// the lidar frame (nullptr for frames that are not stored).
  virtual void onFrame(const MappingFrame& frame, const std::shared_ptr<const Scan>& cloud) = 0;
  /// Selector thread, after every candidate.
  virtual void onCandidate(CandidateEvent event) = 0;
};

}  // namespace rigcal::pipeline
