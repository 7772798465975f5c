#pragma once
// Static calibration's last step: the floor both lidars stand on, used as a shared reference.
//
// Parked in a bay, the roof lidar sees floor only far out while a tilted side lidar sees mostly floor close
// by, so the ensemble's cost leaves the side lidar's tilt about its viewing direction weak (measured 0.2-0.4°
// off at the cost's minimum). Each lidar's own floor plane is fitted in its own frame instead: the source's
// floor normal, mapped into the target frame, must be the target's floor normal (fixes roll and pitch) and
// the source origin's height above it must be the target's floor height (fixes the height). Then only
// yaw about the floor normal and the translation along the floor are left: a point-to-plane ICP over the
// off-floor points, restricted to those three directions (the floor constraints stay exact), refines them.
#include <cstddef>
#include <memory>
#include <string>

#include <Eigen/Core>

#include "rigcal/core/pose.hpp"
#include "rigcal/core/scan.hpp"

namespace rigcal::calib {

struct SharedGroundSettings {
  double ransac_inlier_distance = 0.05;  // m: RANSAC's band (accumulated floors are a few cm thick)
  double refit_inlier_distance = 0.025;  // m: the least-squares refits keep points this close
  double min_below_sensor = 0.5;         // m: floor candidates lie at least this far below the sensor
  double max_floor_range = 25.0;         // m: farther floor is too thin a stripe to add anything
  std::size_t min_floor_points = 300;
  double max_up_deviation_deg = 30.0;    // the floor's normal this close to the expected up
  double off_floor_height = 0.15;        // m: points higher above the floor are structure for the ICP
  double structure_voxel = 0.05;         // m: both clouds' structure voxelised for the ICP
  double max_correspondence = 0.2;       // m: first ICP iterations; halved down to min_correspondence
  double min_correspondence = 0.05;
  int max_iterations = 60;
  /// A refinement is small by nature: a larger correction means a floor was mistaken (a crate top, a
  /// ramp) and the result is left as the ensemble had it.
  double max_correction_m = 0.10;
  double max_correction_deg = 1.5;
  /// ICP directions with less than this share of the largest eigenvalue are left alone (a bay with one
  /// wall fixes nothing along it).
  double min_information_share = 1e-3;
};

struct SharedGroundRefinement {
  bool applied = false;
  std::string note;  // why it was not applied (one line), empty when applied
  Pose T_target_source = Pose::Identity();
  Eigen::Vector3d floor_normal = Eigen::Vector3d::UnitZ();  // the target's floor, target frame (when found)
  double tilt_correction_deg = 0.0;     // roll/pitch change from the floor normals
  double height_correction_m = 0.0;     // along the floor normal
  double yaw_correction_deg = 0.0;      // about the floor normal, from the ICP
  double planar_correction_m = 0.0;     // along the floor, from the ICP
  std::size_t target_floor_points = 0, source_floor_points = 0, matches = 0;
  double seconds = 0.0;
};

/// The target's side, built once and shared by every calibration lidar: its floor plane and the
/// structure above it (normals for the ICP). `up_in_target` is the expected up in the target's frame (the
/// base's z). Never throws for bad data: without a floor, ok() is false and refine() returns unchanged.
class SharedGroundReference {
 public:
  SharedGroundReference(const Scan& target, const Eigen::Vector3d& up_in_target,
                        const SharedGroundSettings& settings = {});
  ~SharedGroundReference();
  SharedGroundReference(const SharedGroundReference&) = delete;
  SharedGroundReference& operator=(const SharedGroundReference&) = delete;

  [[nodiscard]] bool ok() const;
  [[nodiscard]] double buildSeconds() const { return build_seconds_; }

  /// `T_target_source` is the ensemble's result. Without a floor in the source (or with an implausibly
  /// large correction) applied = false and T_target_source is returned unchanged.
  [[nodiscard]] SharedGroundRefinement refine(const Scan& source, const Pose& T_target_source) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  SharedGroundSettings settings_;
  double build_seconds_ = 0.0;
};

}  // namespace rigcal::calib
