#include "local_map.hpp"

#include <algorithm>
#include <chrono>

#include <sys/resource.h>
#include <unistd.h>

#include "rigcal/registration/voxel_grid.hpp"

namespace rigcal::pipeline {

namespace reg = registration;

namespace {

/// voxelDownsample of the keyframes' points one after the other, by merging their voxel orders (bit for bit).
template <class Clouds>
reg::PointCloud voxelised(const Clouds& clouds, double leaf) {
  std::vector<const reg::VoxelOrderedCloud*> keyframes;
  keyframes.reserve(clouds.size());
  for (const auto& k : clouds) keyframes.push_back(k.get());
  return reg::voxelDownsampleConcatenation(keyframes, leaf);
}

template <class Clouds>
std::shared_ptr<const reg::Target> buildTarget(const Clouds& clouds, const config::Parameters& params, bool use_ndt,
                                               int threads) {
  reg::PointCloud merged = voxelised(clouds, params.leaf_size_local_map);
  reg::TargetOptions o;
  o.num_threads = threads;
  if (use_ndt) o.ndt_resolutions = {params.mapper_resolution};
  else o.normals_and_covariances = true;
  return std::make_shared<const reg::Target>(std::move(merged), o);
}

}  // namespace

LocalMap::LocalMap(const config::Parameters& params, bool use_ndt, bool deterministic)
    : params_(params), use_ndt_(use_ndt), deterministic_(deterministic) {}

void LocalMap::beforeRegistration() {
  swapInPendingTarget(false);
  if (rebuild_wanted_ && !pending_target_.valid()) launchBuild();
}

void LocalMap::swapInPendingTarget(bool now) {
  if (!pending_target_.valid()) return;
  if (!target_) {  // a first or restarted map: nothing else to register against, wait for it
    target_ = pending_target_.get();
    return;
  }
  ++scans_since_launch_;
  const bool ready = pending_target_.wait_for(std::chrono::seconds(0)) == std::future_status::ready;
  if (!now && (deterministic_ ? scans_since_launch_ < kSwapAfterScans : !ready)) return;
  target_ = pending_target_.get();
}

void LocalMap::addKeyframe(const Scan& deskewed, const Pose& T_map_lidar, bool restart) {
  auto k = std::make_shared<const reg::VoxelOrderedCloud>(
      reg::transformed(reg::voxelDownsample(reg::fromScan(deskewed), params_.leaf_size_local_map), T_map_lidar),
      params_.leaf_size_local_map);
  if (restart) local_.clear();
  all_keyframes_.push_back(k);
  local_.push_back(std::move(k));
  while (int(local_.size()) > std::max(1, params_.local_map_num_keyframes)) local_.pop_front();
  // A first or restarted map is built in the background too: the scan that seeds it returns at once and
  // the next one (a sweep period later) finds it ready, or waits for the rest. Either way every scan
  // registers against the same map, whatever the timing: offline runs stay deterministic.
  if (restart || !target_) {
    target_.reset();
    launchBuild();
    return;
  }
  if (!deterministic_ && pending_target_.valid() &&
      pending_target_.wait_for(std::chrono::seconds(0)) != std::future_status::ready) {
    // Real time: never wait for the last build. It is swapped in when ready; this keyframe's map follows.
    rebuild_wanted_ = true;
    return;
  }
  swapInPendingTarget(true);
  launchBuild();
}

void LocalMap::launchBuild() {
  std::vector<KeyframeCloud> clouds(local_.begin(), local_.end());
  scans_since_launch_ = 0;
  rebuild_wanted_ = false;
  // Real time: one build thread, so the registering threads keep one core to themselves (a build on
  // both cores slows both halves of every registration's parallel loop). Offline: as fast as possible.
  // The Target is the same whatever the thread count.
  const int threads = deterministic_ ? std::max(1, params_.mapper_num_threads) : 1;
  pending_target_ = std::async(std::launch::async, [clouds = std::move(clouds), p = params_, ndt = use_ndt_, threads] {
    // Below the registering thread: a build (~5x one registration's CPU) must not stretch the scans
    // that register meanwhile, on two cores. Its helper threads inherit the niceness.
    ::setpriority(PRIO_PROCESS, id_t(::gettid()), kBuildNiceness);
    return buildTarget(clouds, p, ndt, threads);
  });
}

reg::PointCloud LocalMap::allKeyframes() const { return voxelised(all_keyframes_, params_.leaf_size_local_map); }

}  // namespace rigcal::pipeline
