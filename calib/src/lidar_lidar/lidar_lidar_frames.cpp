// One calibration frame: its source (range-limited, deskewed calibration cloud) and its augmented target,
// sized so that the deadline leaves time to register.
#include "lidar_lidar_calibrator.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <sstream>

#include "rigcal/calib/lidar_lidar/augmented_target.hpp"
#include "rigcal/calib/lidar_lidar/calibration_budget.hpp"
#include "rigcal/registration/voxel_grid.hpp"

namespace rigcal::calib::detail {

/// Under a short deadline the first target may use at most this share of the time left.
constexpr double kFirstTargetShare = 0.25;
/// How far the first target's voxels may grow: at 4x the dense-map leaf (0.2 m by default) a surface still
/// has a target point within the score's 0.1 m of any source point on it; beyond that clouds are dropped.
constexpr double kMaxFirstTargetLeafScale = 4.0;

namespace {
/// The voxel leaf that brings a target expected to take `seconds` to build down to `allowed`: on surfaces
/// the point count goes with 1/leaf², so the leaf grows with sqrt(seconds / allowed), capped.
double firstTargetLeaf(double leaf, double seconds, double allowed) {
  if (!(leaf > 0.0) || !(allowed > 0.0) || seconds <= allowed) return leaf;
  return leaf * std::min(kMaxFirstTargetLeafScale, std::sqrt(seconds / allowed));
}
}  // namespace

FrameBuild Calibrator::buildFrame(std::size_t i, double reserve) {
  const FrameBuild built = buildFrameTarget(i, reserve);
  // Frames are built in order and none after one that ran out of time: what only the earlier targets read
  // can go now (issue #18: front_left's ~100 mapping clouds had lived through its whole calibration).
  if (targets_done_) targets_done_(built == FrameBuild::kOutOfTime ? data_.frames.size() : i + 1);
  return built;
}

AugmentedTargetOptions Calibrator::targetOptions() const {
  AugmentedTargetOptions to = opt_.target;
  to.num_threads = opt_.num_threads;
  to.deadline = deadline_;
  // Once the first frame's ensemble has moved the estimate, later targets need only the mapping points near
  // the source under it (and under the guess, whose score must stay exact): ~30 % fewer points on the
  // parking lot than the box under the guess, and the build goes with the points.
  if (!frames_.empty() && !samePose(best_, data_.T_mapping_calib_guess)) {
    to.near_poses = {data_.T_mapping_calib_guess, best_};
    to.near_radius = nearTargetRadius(params_);
  }
  return to;
}

FramePreparationInputs Calibrator::preparationInputs(std::size_t i, int num_threads) const {
  FramePreparationInputs in;
  in.index = i;
  in.deskewed = data_.frames[i].deskewed;
  in.target = targetOptions();
  in.window = targetWindowClouds(data_, i, params_, in.target.max_clouds);
  in.num_threads = num_threads;
  return in;
}

std::size_t Calibrator::minSourcePoints() const {
  return std::size_t(std::max(params_.min_calibration_pointcloud_size, 10));
}

FrameBuild Calibrator::buildFrameTarget(std::size_t i, double reserve) {
  std::ostringstream skip;
  skip << "frame " << i << ": ";
  // Prepared on the second core while the previous frame's target was built and confirmed, or now.
  std::optional<PreparedFrame> prefetched = prefetch_.take(i);
  PreparedFrame p = prefetched ? std::move(*prefetched)
                               : prepareFrame(preparationInputs(i, opt_.num_threads), params_, minSourcePoints());
  const auto tp = Clock::now();
  // Every step of a frame's preparation that cannot be interrupted is followed by a look at the deadline.
  if (p.out_of_time || stopped()) return FrameBuild::kOutOfTime;
  if (p.source.size() < minSourcePoints()) {
    skip << p.source.size() << " source points within the calibration range (min_calibration_pointcloud_size "
         << params_.min_calibration_pointcloud_size << ")";
    out_.frames_skipped.push_back(skip.str());
    return FrameBuild::kSkipped;
  }
  Frame f;
  f.index = i;
  f.source = std::move(p.source);
  auto cloud = std::move(p.cloud);
  std::size_t clouds = p.clouds;
  // What the first frame still needs (perhaps a voxel pass over these points, a target build over them, a
  // registration) takes longer than the crop did: with less time left, stop now rather than start an uncut
  // voxel pass that overshoots the deadline (a 0.5 s share ended 0.1-0.18 s late on a loaded machine).
  if (frames_.empty() && !fits(deadline_, p.crop_seconds)) return FrameBuild::kOutOfTime;
  // The first frame must leave time to register: under a short deadline its target is thinned rather
  // than not built at all. First by coarser voxels over every mapping cloud of the window: dropping clouds
  // (below) leaves holes where no remaining cloud looked, and a tilted lidar looks where a 32-beam map has
  // few rings (yard-corners at the default deadline: the first target's inlier ratio 0.43-0.50, the
  // rear lidar's first frame 4.6 cm off; see firstTargetLeaf).
  const double allowed = kFirstTargetShare * secondsLeft(deadline_);
  const std::size_t dense_points = cloud.size();
  if (frames_.empty() && seconds_per_point_ * double(cloud.size()) > allowed) {
    const double leaf = firstTargetLeaf(params_.leaf_size_dense_map, seconds_per_point_ * double(cloud.size()), allowed);
    if (leaf > params_.leaf_size_dense_map) cloud = registration::voxelDownsample(cloud, leaf);
  }
  if (frames_.empty() && clouds > 1 && seconds_per_point_ * double(cloud.size()) > allowed) {
    AugmentedTargetOptions to = targetOptions();
    const double points_per_cloud = double(dense_points) / double(clouds);  // the rebuild is at the dense leaf
    to.max_clouds = std::max<std::size_t>(1, std::size_t(allowed / (seconds_per_point_ * points_per_cloud)));
    cloud = augmentedCloud(data_, i, f.source, params_, to, &clouds);
    if (stopped()) return FrameBuild::kOutOfTime;
  }
  // Do not start a build that the deadline would cut (wasted work: the build stops at the deadline), nor
  // one that leaves less than `reserve`. Judged on the cropped cloud: a later frame's near crop is a
  // fraction of the first frame's box (the street's VLP-16 behind a VLS-128 map).
  const double prepare_seconds = p.source_seconds + p.crop_seconds + since(tp);
  if (!fits(deadline_, seconds_per_point_ * double(cloud.size()) + reserve)) return FrameBuild::kOutOfTime;
  if (cloud.size() < 100) {
    skip << "augmented target has " << cloud.size() << " points from " << clouds << " mapping clouds";
    out_.frames_skipped.push_back(skip.str());
    return FrameBuild::kSkipped;
  }
  // A later frame's build and confirmation leave the second core idle for stretches: the next frame's source
  // and crop (single-threaded) go there. Its crop is near the best as it stands now, one confirmation older
  // than the frame's own build would see: the near radius allows for that (nearTargetRadius).
  if (!frames_.empty() && opt_.num_threads > 1 && i + 1 < data_.frames.size())
    prefetch_.start(preparationInputs(i + 1, 1), params_, minSourcePoints());
  const double n = double(cloud.size());
  registration::TargetOptions topt;
  topt.normals_and_covariances = true;
  topt.ndt_resolutions = {opt_.target.ndt_resolution};
  topt.num_threads = opt_.num_threads;
  topt.deadline = deadline_;  // on a busy machine a build can take several times its estimate
  const auto tt = Clock::now();
  f.target = std::make_shared<const Target>(std::move(cloud), topt);
  if (f.target->stopped()) return FrameBuild::kOutOfTime;
  seconds_per_point_ = since(tt) / n;
  last_prepare_seconds_ = prepare_seconds;
  out_.frames_used.push_back(i);
  frames_.push_back(std::move(f));
  return FrameBuild::kBuilt;
}

}  // namespace rigcal::calib::detail
