#pragma once
// The mapper's local map: the last local_map_num_keyframes keyframes (voxelised, in the map frame) and the
// registration target built from them. A target is built on another thread while registration goes on
// against the previous one; offline (`deterministic`) it is swapped in at a fixed scan after its keyframe,
// waiting for it if needed, so every run registers each scan against the same map; in real time it is
// swapped in as soon as it is ready and never waited for. Private to the pipeline library; used by the
// mapper's thread only.
#include <deque>
#include <future>
#include <memory>
#include <vector>

#include "rigcal/config/parameters.hpp"
#include "rigcal/core/pose.hpp"
#include "rigcal/core/scan.hpp"
#include "rigcal/registration/point_cloud.hpp"
#include "rigcal/registration/target.hpp"
#include "rigcal/registration/voxel_ordered_cloud.hpp"

namespace rigcal::pipeline {

class LocalMap {
 public:
  LocalMap(const config::Parameters& params, bool use_ndt, bool deterministic);

  /// Before each scan's registration: swaps in a target that is due (offline) or ready (real time), and
  /// starts a build a keyframe asked for while the last one was still running.
  void beforeRegistration();
  /// The current target; null before the first keyframe.
  [[nodiscard]] const registration::Target* target() const { return target_.get(); }

  /// Adds a keyframe (`deskewed` in the lidar frame at T_map_lidar); `restart` drops the older ones first.
  void addKeyframe(const Scan& deskewed, const Pose& T_map_lidar, bool restart);

  /// Every keyframe ever added, voxelised together at leaf_size_local_map (map frame): the drive's map.
  [[nodiscard]] registration::PointCloud allKeyframes() const;

 private:
  /// A keyframe's voxelised cloud in the map frame: positions only, without the homogeneous w (always 1),
  /// three quarters of a PointCloud's bytes; a drive keeps every keyframe for the map (issue #18). With its
  /// points' order by map voxel (4 bytes a point), so that each rebuild merges the keyframes' orders instead
  /// of hashing every point of the local map again (the same map, bit for bit).
  using KeyframeCloud = std::shared_ptr<const registration::VoxelOrderedCloud>;

  void swapInPendingTarget(bool now);
  void launchBuild();

  static constexpr int kBuildNiceness = 5;  // weight ~1/3 of the mapper's: slowed, never starved
  static constexpr int kSwapAfterScans = 2;

  config::Parameters params_;
  bool use_ndt_;
  bool deterministic_;
  std::deque<KeyframeCloud> local_;          // the local map's keyframes, oldest first
  std::vector<KeyframeCloud> all_keyframes_;  // every keyframe's cloud (for the map)
  std::shared_ptr<const registration::Target> target_;
  // The target after a new keyframe, swapped in at the kSwapAfterScans-th scan after that keyframe (a fixed
  // point in the scan sequence), waiting for it only if it is not ready by then.
  std::future<std::shared_ptr<const registration::Target>> pending_target_;
  int scans_since_launch_ = 0;
  bool rebuild_wanted_ = false;  // real time: a keyframe came while a build was still running
};

}  // namespace rigcal::pipeline
