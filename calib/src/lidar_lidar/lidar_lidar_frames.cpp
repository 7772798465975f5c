// The calibration frames: each one's source (range-limited, deskewed calibration cloud); the first frame's
// own augmented target, sized so that the deadline leaves time to register; the later frames' shared one.
#include "lidar_lidar_calibrator.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "rigcal/calib/lidar_lidar/augmented_target.hpp"
#include "rigcal/calib/lidar_lidar/calibration_budget.hpp"
#include "rigcal/calib/lidar_lidar/calibration_source.hpp"
#include "rigcal/calib/lidar_lidar/shared_target_cloud.hpp"
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

FrameBuild Calibrator::buildFrame(std::size_t i) {
  const FrameBuild built = buildFrameTarget(i);
  // Frames are built in order: what only this frame's target read can go now, unless later frames still
  // name it (issue #18: front_left's ~100 mapping clouds had lived through its whole calibration).
  if (targets_done_) targets_done_(built == FrameBuild::kOutOfTime ? data_.frames.size() : i + 1);
  return built;
}

FrameBuild Calibrator::prepareSource(std::size_t i, Frame& f) {
  f.index = i;
  SourceOptions so;
  so.covariances = false;  // GICP's, estimated when a GICP first runs on the frame (ensureSourceCovariances)
  so.num_threads = opt_.num_threads;
  f.source = calib::buildSource(*data_.frames[i].deskewed, params_, so);
  // Every step of a frame's preparation that cannot be interrupted is followed by a look at the deadline.
  if (stopped()) return FrameBuild::kOutOfTime;
  if (f.source.size() < std::size_t(std::max(params_.min_calibration_pointcloud_size, 10))) {
    std::ostringstream skip;
    skip << "frame " << i << ": " << f.source.size()
         << " source points within the calibration range (min_calibration_pointcloud_size "
         << params_.min_calibration_pointcloud_size << ")";
    out_.frames_skipped.push_back(skip.str());
    return FrameBuild::kSkipped;
  }
  return FrameBuild::kBuilt;
}

FrameBuild Calibrator::buildFrameTarget(std::size_t i) {
  const auto tb = Clock::now();
  Frame f;
  if (const FrameBuild b = prepareSource(i, f); b != FrameBuild::kBuilt) return b;
  AugmentedTargetOptions to = opt_.target;
  to.num_threads = opt_.num_threads;
  to.deadline = deadline_;
  std::size_t clouds = 0, cropped = 0;
  const auto tc = Clock::now();
  auto cloud = augmentedCloud(data_, i, f.source, params_, to, &clouds, &cropped);
  if (stopped()) return FrameBuild::kOutOfTime;
  // What the first frame still needs (perhaps a voxel pass over these points, a target build over them, a
  // registration) takes longer than the crop did: with less time left, stop now rather than start an uncut
  // voxel pass that overshoots the deadline (a 0.5 s share ended 0.1-0.18 s late on a loaded machine).
  if (!fits(deadline_, since(tc))) return FrameBuild::kOutOfTime;
  // The first frame must leave time to register: under a short deadline its target is thinned rather
  // than not built at all. First by coarser voxels over every mapping cloud of the window: dropping clouds
  // (below) leaves holes where no remaining cloud looked, and a tilted lidar looks where a 32-beam map has
  // few rings (yard-corners at the default deadline: the first target's inlier ratio 0.43-0.50, the
  // rear lidar's first frame 4.6 cm off; see firstTargetLeaf).
  const double allowed = kFirstTargetShare * secondsLeft(deadline_);
  const std::size_t dense_points = cloud.size();
  if (seconds_per_point_ * double(cloud.size()) > allowed) {
    const double leaf = firstTargetLeaf(params_.leaf_size_dense_map, seconds_per_point_ * double(cloud.size()), allowed);
    if (leaf > params_.leaf_size_dense_map) cloud = registration::voxelDownsample(cloud, leaf);
  }
  if (clouds > 1 && seconds_per_point_ * double(cloud.size()) > allowed) {
    const double points_per_cloud = double(dense_points) / double(clouds);  // the rebuild is at the dense leaf
    to.max_clouds = std::max<std::size_t>(1, std::size_t(allowed / (seconds_per_point_ * points_per_cloud)));
    cloud = augmentedCloud(data_, i, f.source, params_, to, &clouds, &cropped);
    if (stopped()) return FrameBuild::kOutOfTime;
  }
  // Do not start a build that the deadline would cut (wasted work: the build stops at the deadline).
  const double prepare_seconds = since(tb);
  if (!fits(deadline_, seconds_per_point_ * double(cloud.size()))) return FrameBuild::kOutOfTime;
  if (cloud.size() < 100) {
    std::ostringstream skip;
    skip << "frame " << i << ": augmented target has " << cloud.size() << " points from " << clouds
         << " mapping clouds";
    out_.frames_skipped.push_back(skip.str());
    return FrameBuild::kSkipped;
  }
  f.target = buildTarget(std::move(cloud), to.ndt_resolution);
  if (f.target == nullptr) return FrameBuild::kOutOfTime;
  last_prepare_seconds_ = prepare_seconds;
  out_.frames_used.push_back(i);
  frames_.push_back(std::move(f));
  return FrameBuild::kBuilt;
}

std::shared_ptr<const Target> Calibrator::buildTarget(PointCloud cloud, double ndt_resolution) {
  const double n = double(cloud.size());
  registration::TargetOptions topt;
  topt.normals_and_covariances = true;
  topt.ndt_resolutions = {ndt_resolution};
  topt.num_threads = opt_.num_threads;
  topt.deadline = deadline_;  // on a busy machine a build can take several times its estimate
  const auto tt = Clock::now();
  auto target = std::make_shared<const Target>(std::move(cloud), topt);
  if (target->stopped()) return nullptr;
  if (n > 0.0) seconds_per_point_ = since(tt) / n;
  return target;
}

bool Calibrator::laterTargets(std::size_t& next, std::size_t first_frames) {
  // Every other frame, scored together from now on, against one target they share (SharedTargetCloud): once
  // the first frame's ensemble has moved the estimate, a frame needs only the mapping points near its source
  // under it (and under the guess, whose score must stay exact), and the frames' neighbourhoods overlap.
  const auto t = Clock::now();
  std::vector<Pose> near_poses{data_.T_mapping_calib_guess};
  if (!samePose(best_, data_.T_mapping_calib_guess)) near_poses.push_back(best_);
  SharedTargetCloud shared(data_, params_, opt_.target.max_clouds);
  std::vector<Frame> pending;
  bool targets_cut = false;
  double last_voxels_added = 0.0;
  while (next < data_.frames.size()) {
    // With one more frame, the shared build must still leave time for what makes one estimate of the frames:
    // the grown set's rescore (else the new frames are dropped), one confirming ICP per frame and the batched
    // chain. Without that reserve a loaded machine spent the whole share on targets and never ran the
    // batched ICP (parking lot at load 7: front_right 1.0-1.3 cm off). The next crop is expected to take as
    // long as the last frame's preparation and to add as many voxels.
    const std::size_t grown = frames_.size() + pending.size() + 1;
    const double reserve = 2.5 * double(grown) / double(first_frames) * score_seconds_ +
                           batchedChainEstimate(grown) * 4.0 / 3.0;
    const double build = seconds_per_point_ * (double(shared.voxels()) + 1.2 * last_voxels_added);
    if (!fits(deadline_, 1.2 * last_prepare_seconds_ + build + reserve)) {
      targets_cut = true;
      break;
    }
    const auto tp = Clock::now();
    Frame f;
    const FrameBuild b = prepareSource(next, f);
    if (b == FrameBuild::kOutOfTime) {
      targets_cut = true;
      break;
    }
    ++next;
    if (b == FrameBuild::kSkipped) continue;
    const std::size_t before = shared.voxels();
    if (!shared.add(f.index, f.source, near_poses, nearTargetRadius(params_), deadline_)) {
      targets_cut = true;  // the crop was cut: this frame is not (wholly) in the cloud
      break;
    }
    last_voxels_added = double(shared.voxels() - before);
    last_prepare_seconds_ = since(tp);
    pending.push_back(std::move(f));
  }
  if (!pending.empty()) {
    auto target = shared.voxels() >= 100 && !stopped() ? buildTarget(shared.cloud(), opt_.target.ndt_resolution)
                                                       : nullptr;
    if (target == nullptr && stopped()) targets_cut = true;  // the frames cropped so far are lost with it
    if (target != nullptr) {
      for (Frame& f : pending) {
        f.target = target;
        f.anchor = shared.anchor(f.index);
        out_.frames_used.push_back(f.index);
        frames_.push_back(std::move(f));
      }
    } else if (!targets_cut) {
      out_.frames_skipped.push_back("later frames: their shared target has " + std::to_string(shared.voxels()) +
                                    " points");
    }
  }
  // The mapping clouds are read by no target from now on.
  if (targets_done_) targets_done_(data_.frames.size());
  seconds_.targets += since(t);
  // Each frame's own view of the best (one ICP): if the deadline cuts the plan after this, the frames built
  // still count as evidence for the verdict (lidar_lidar_verdict.hpp).
  const auto te = Clock::now();
  for (std::size_t k = first_frames; k < frames_.size() && !stopped(); ++k) confirmOnFrame(k);
  seconds_.ensemble += since(te);
  return targets_cut;
}

}  // namespace rigcal::calib::detail
