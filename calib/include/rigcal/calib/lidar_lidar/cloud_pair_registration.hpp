#pragma once
// One pair of clouds (two lidars, or two scans), registered with the lidar-lidar calibration's own
// ensemble and score (lidar_lidar_calibration.hpp): the target plays the mapping lidar's map, the source a
// single calibration frame of a vehicle standing still (no deskew, no trajectory). Before it, the global
// stage (cloud_pair_global_search.hpp) finds the basin from a far guess; after it, the overlap of the two
// clouds and the information per direction (registration_information.hpp) say how far to trust it.
#include <filesystem>
#include <optional>
#include <string>

#include "rigcal/calib/lidar_lidar/cloud_pair_global_search.hpp"
#include "rigcal/calib/lidar_lidar/lidar_lidar_calibration.hpp"
#include "rigcal/calib/lidar_lidar/registration_information.hpp"
#include "rigcal/config/parameters.hpp"
#include "rigcal/core/pose.hpp"
#include "rigcal/core/scan.hpp"

namespace rigcal::calib {

struct CloudPairOptions {
  Pose T_target_source_guess = Pose::Identity();
  bool global_search = true;
  GlobalSearchSettings global;
  double deadline_s = 10.0;        // the ensemble's (calibration_deadline_s)
  /// The deadline also bounds what comes before the ensemble (targets, global stage): the ensemble gets
  /// what is left (at least a tenth). Static calibration shares one deadline among its lidars this way.
  bool deadline_covers_global = false;
  bool exhaustive = false;         // upstream's exhaustive pass in the time left (off: stop when refined)
  double overlap_distance = 0.3;   // m: a point overlaps when the other cloud has a point this close
  double min_overlap = 0.02;       // under this share of the source the clouds do not overlap
  /// Under this share of the source within calibration_eval_max_corr_distance at the result, the "match"
  /// is structure that merely looks alike (the full-turn global stage turned one half of a street onto
  /// the other: 0.11); real pairs measured 0.86-0.998.
  double min_inlier_ratio = 0.25;
  int num_threads = 2;
};

struct CloudPairResult {
  bool ok = false;
  std::string failure;           // one line when !ok
  bool not_enough_data = false;  // failed for lack of data (no overlap, too few points), not in registration
  Pose T_target_source_guess = Pose::Identity();
  Pose T_target_source = Pose::Identity();
  std::optional<GlobalSearchResult> global;
  CalibrationScore guess_score;  // the ensemble's score at the user's guess
  CalibrationScore final_score;  // at T_target_source (after the final point-to-plane polish)
  LidarLidarResult ensemble;     // its initial_score is at the global stage's result
  double source_overlap = 0.0;   // share of the source's points with a target point within overlap_distance
  double target_overlap = 0.0;   // share of the target's points (in the source's range) with a source point near
  RegistrationInformation information;
  std::size_t target_points = 0, source_points = 0;  // finite points read
  double seconds = 0.0;
};

/// Never throws for bad data: empty clouds, no overlap and failed registrations give ok = false and a
/// one-line failure.
CloudPairResult registerCloudPair(const Scan& target, const Scan& source, const config::Parameters& params,
                                  const CloudPairOptions& options);

/// registration.yaml: T_target_source as x y z roll pitch yaw (m, rad; R = Rz·Ry·Rx as calibration.yaml)
/// and as a 4×4 matrix, the scores, the global stage's basins, overlap and information per direction.
void writeRegistrationYaml(const std::filesystem::path& path, const CloudPairResult& result,
                           const std::string& target_name, const std::string& source_name);

/// target.pcd, source_before.pcd, source_after.pcd (the source through the guess and the result, in the
/// target frame) and overlay.png (calib's before/after overview), in `dir`.
void writeRegistrationClouds(const std::filesystem::path& dir, const Scan& target, const Scan& source,
                             const CloudPairResult& result);

}  // namespace rigcal::calib
