#pragma once
// The mapping lidar's mapper. Each scan: crop to the mapping range → deskew with the motion model
// (constant velocity from the last poses, motion_model.hpp) → voxelise → register against the local map
// (our GICP or NDT, per mapping_registrator; local_map.hpp) from the model's guess → re-deskew with the
// registered motion → classify the frame by the upstream rules (FrameTracker) → update the model and the
// map. A registration that fails its convergence or fitness check makes the frame lost (pose = the
// prediction) and the map is not fed from it. The local map holds the last local_map_num_keyframes
// keyframes, restarting at a lost keyframe; only a whole sweep seeds it (seed_sweep_check.hpp).
// Single-threaded: the mapper stage owns it.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "rigcal/config/parameters.hpp"
#include "rigcal/core/scan.hpp"
#include "rigcal/pipeline/frame_tracker.hpp"

namespace rigcal::pipeline {

/// What one registration reported (kept small: it goes into every frame event).
struct RegistrationSummary {
  std::string status;  // registration::toString(Status), or "first" for the map's first frame
  int iterations = 0;
  double inlier_ratio = 0.0;
  double rmse = 0.0;
  bool ok = false;  // passed the convergence and fitness checks
};

struct MapperOutput {
  bool registered = false;     // false: the scan was skipped (see skipped_reason)
  std::string skipped_reason;  // too few points, mapper full
  MappingFrame frame;
  RegistrationSummary registration;
  /// Keyframes only: the deskewed cloud in the lidar frame at frame.stamp_ns, voxelised at
  /// leaf_size_dense_map: positions only (x, y, z; the other arrays are empty: never point(), filter()). With
  /// Mapper::deferPostPoseWork() left empty until Mapper::finishFrame().
  std::shared_ptr<const Scan> cloud;
  /// Keyframes, deferred post-pose work only: the deskewed scan `cloud` is made from.
  std::shared_ptr<const Scan> deskewed;
};

class Mapper {
 public:
  /// Fitness check: at least this fraction of the source within mapper_max_correspondence_distance
  /// (GICP) or 1 m (NDT) of the local map.
  static constexpr double kMinInlierRatio = 0.3;

  /// `deterministic` (offline): a rebuilt local map is swapped in at a fixed scan after its keyframe,
  /// waiting for it if needed. Otherwise (real time) it is swapped in as soon as it is ready: never waits.
  explicit Mapper(const config::Parameters& params, bool deterministic = true);
  ~Mapper();
  Mapper(const Mapper&) = delete;
  Mapper& operator=(const Mapper&) = delete;

  /// `scan` as decoded (cropRange to mapping_min/max_range is the mapper's first step).
  MapperOutput process(Scan scan);
  /// With `defer`, process() stops once the pose is known: a keyframe's dense cloud (voxelised from
  /// `deskewed`) and feeding a keyframe to the local map (milliseconds) are left to finishFrame(), which
  /// the caller runs after publishing the pose (the next process() runs it if the caller did not).
  void deferPostPoseWork(bool defer);
  /// Completes the last process() output: fills out.cloud from out.deskewed and feeds the local map.
  void finishFrame(MapperOutput& out);

  [[nodiscard]] const FrameTracker& tracker() const;
  /// mapping_max_frames frames are stored: further scans are skipped.
  [[nodiscard]] bool done() const;
  /// Points of the current local map target.
  [[nodiscard]] std::size_t localMapPoints() const;
  /// Every keyframe's cloud (voxel leaf_size_local_map) in the map frame, merged at leaf_size_local_map.
  [[nodiscard]] std::shared_ptr<const Scan> mapCloud() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Keeps points with range in [min_range, max_range) and finite coordinates.
void cropRange(Scan& scan, double min_range, double max_range);

}  // namespace rigcal::pipeline
