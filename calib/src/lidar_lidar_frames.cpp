// One calibration frame: its source (range-limited, deskewed calibration cloud) and its augmented target,
// sized so that the deadline leaves time to register.
#include "lidar_lidar_calibrator.hpp"

#include <algorithm>
#include <sstream>

#include "rigcal/calib/augmented_target.hpp"
#include "rigcal/calib/calibration_budget.hpp"
#include "rigcal/calib/calibration_source.hpp"

namespace rigcal::calib::detail {

/// Under a short deadline the first target may use at most this share of the time left.
constexpr double kFirstTargetShare = 0.25;

void Calibrator::buildFrame(std::size_t i) {
  const auto& df = data_.frames[i];
  std::ostringstream skip;
  skip << "frame " << i << ": ";
  const auto tb = Clock::now();
  Frame f;
  f.index = i;
  SourceOptions so;
  so.num_threads = opt_.num_threads;
  f.source = buildSource(*df.deskewed, params_, so);
  // Every step of a frame's preparation that cannot be interrupted is followed by a look at the deadline.
  if (stopped()) return;
  if (f.source.size() < std::size_t(std::max(params_.min_calibration_pointcloud_size, 10))) {
    skip << f.source.size() << " source points within the calibration range (min_calibration_pointcloud_size "
         << params_.min_calibration_pointcloud_size << ")";
    out_.frames_skipped.push_back(skip.str());
    return;
  }
  AugmentedTargetOptions to = opt_.target;
  to.num_threads = opt_.num_threads;
  to.deadline = deadline_;
  std::size_t clouds = 0, cropped = 0;
  auto cloud = augmentedCloud(data_, i, f.source, params_, to, &clouds, &cropped);
  if (stopped()) return;
  // The first frame must leave time to register: under a short deadline its target is built from
  // fewer mapping clouds (the keyframe's own always among them) rather than not at all.
  const double allowed = kFirstTargetShare * secondsLeft(deadline_);
  if (frames_.empty() && clouds > 1 && seconds_per_point_ * double(cloud.size()) > allowed) {
    const double points_per_cloud = double(cloud.size()) / double(clouds);
    to.max_clouds = std::max<std::size_t>(1, std::size_t(allowed / (seconds_per_point_ * points_per_cloud)));
    cloud = augmentedCloud(data_, i, f.source, params_, to, &clouds, &cropped);
    if (stopped()) return;
  }
  // Do not start a build that the deadline would cut (wasted work: the build stops at the deadline).
  if (!fits(deadline_, seconds_per_point_ * double(cloud.size()))) {
    out_.deadline_reached = true;
    return;
  }
  if (cloud.size() < 100) {
    skip << "augmented target has " << cloud.size() << " points from " << clouds << " mapping clouds";
    out_.frames_skipped.push_back(skip.str());
    return;
  }
  const double n = double(cloud.size());
  registration::TargetOptions topt;
  topt.normals_and_covariances = true;
  topt.ndt_resolutions = {to.ndt_resolution};
  topt.num_threads = opt_.num_threads;
  topt.deadline = deadline_;  // on a busy machine a build can take several times its estimate
  f.target = std::make_shared<const Target>(std::move(cloud), topt);
  if (f.target->stopped()) {
    out_.deadline_reached = true;
    return;
  }
  seconds_per_point_ = since(tb) / n;
  last_build_seconds_ = since(tb);
  out_.frames_used.push_back(i);
  frames_.push_back(std::move(f));
}

}  // namespace rigcal::calib::detail
