#include "rigcal/calib/lidar_lidar/stillness_watch.hpp"

#include <algorithm>
#include <iomanip>
#include <sstream>

#include "rigcal/registration/icp.hpp"
#include "rigcal/registration/target.hpp"
#include "rigcal/registration/voxel_grid.hpp"

namespace rigcal::calib {
namespace {

// Fine enough that a 1 cm shift moves the ICP minimum, coarse enough that a 64-beam sweep registers in a
// few ms.
constexpr double kVoxel = 0.2;
constexpr std::size_t kMinPoints = 50;

}  // namespace

struct SweepRegistrar::Impl {
  registration::Target reference;
};

SweepRegistrar::SweepRegistrar(const Scan& reference) {
  registration::TargetOptions to;
  to.normals_and_covariances = true;
  to.num_threads = 2;
  impl_ = std::make_unique<Impl>(
      Impl{registration::Target(registration::voxelDownsample(registration::fromScan(reference), kVoxel), to)});
}

SweepRegistrar::~SweepRegistrar() = default;

std::optional<Pose> SweepRegistrar::motion(const Scan& sweep, const Pose& start) const {
  const auto source = registration::voxelDownsample(registration::fromScan(sweep), kVoxel);
  if (source.size() < kMinPoints || impl_->reference.size() < kMinPoints) return std::nullopt;
  registration::IcpParams p;
  p.method = registration::IcpMethod::kPointToPlane;
  p.max_correspondence_distance = 1.0;  // a moving vehicle's sweeps are still matched a metre apart
  p.max_iterations = 50;
  p.coarse_to_fine = true;
  p.check_degeneracy = false;
  p.num_threads = 2;
  const auto r = registration::alignIcp(impl_->reference, source, start, p);
  if (!r.T_target_source.matrix().allFinite() || r.status == registration::Status::kTooFewCorrespondences ||
      r.status == registration::Status::kInvalidInput)
    return std::nullopt;
  return r.T_target_source;
}

StillnessWatch::StillnessWatch(const config::Parameters& params, double settle_s)
    : settle_s_(settle_s), limit_m_(params.static_max_motion_m), limit_deg_(params.static_max_motion_deg) {}

StillnessWatch::~StillnessWatch() = default;

bool StillnessWatch::add(const Scan& sweep) {
  if (settled_at_) return true;
  ++sweeps_;
  if (!first_stamp_) first_stamp_ = sweep.stamp_ns;
  last_stamp_ = sweep.stamp_ns;
  bool still = false;
  if (reference_) {
    const auto T = reference_->motion(sweep);
    still = T && T->translation().norm() <= limit_m_ &&
            rad2deg(rotationAngleBetween(*T, Pose::Identity())) <= limit_deg_;
  }
  if (!still) {  // this sweep starts a new stretch
    reference_ = std::make_unique<SweepRegistrar>(sweep);
    reference_stamp_ = sweep.stamp_ns;
    return false;
  }
  const double stretch = toSeconds(sweep.stamp_ns - reference_stamp_);
  longest_still_s_ = std::max(longest_still_s_, stretch);
  if (stretch + 1e-6 >= settle_s_) {
    settled_at_ = sweep.stamp_ns;
    reference_.reset();
  }
  return settled();
}

double StillnessWatch::waitedS() const {
  if (!first_stamp_) return 0.0;
  return toSeconds((settled_at_ ? *settled_at_ : *last_stamp_) - *first_stamp_);
}

std::string StillnessWatch::neverStillMessage() const {
  std::ostringstream o;
  o << std::fixed << std::setprecision(2) << "the vehicle was never still for " << settle_s_
    << " s: watched " << sweeps_ << " mapping sweeps over " << waitedS() << " s, the longest still stretch "
    << longest_still_s_ << " s (limits static_max_motion_m " << std::setprecision(3) << limit_m_
    << " m, static_max_motion_deg " << std::setprecision(2) << limit_deg_
    << " deg): park the vehicle and record again";
  return o.str();
}

}  // namespace rigcal::calib
