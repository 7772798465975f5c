#include "rigcal/calib/lidar_lidar/static_calibration.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "rigcal/calib/base_lidar/base_lidar_calibration.hpp"
#include "rigcal/calib/lidar_lidar/lidar_lidar_verdict.hpp"
#include "rigcal/calib/lidar_lidar/shared_ground_refinement.hpp"
#include "rigcal/calib/lidar_lidar/stillness_watch.hpp"
#include "rigcal/registration/icp.hpp"
#include "rigcal/registration/target.hpp"
#include "rigcal/registration/voxel_grid.hpp"
#include "rigcal/core/text_format.hpp"

namespace rigcal::calib {
namespace {

using Clock = std::chrono::steady_clock;

double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

// The accumulated clouds: 2 cm centroids average the sweeps' range noise without blurring any edge.
constexpr double kAccumulationVoxel = 0.02;
// Metres the base-lidar crop box grows by around the vehicle's footprint (a 64-beam roof lidar at 2 m
// first meets the ground ~6 m out; 5 m keeps the box inside a bay's walls).
constexpr double kGroundMargin = 5.0;

// The accumulated pair as a one-frame calibration dataset (for the clouds and the overview writers): the
// mapping cloud at a keyframe with the identity pose, the calibration cloud its only frame.
pipeline::CalibrationDataset staticDataset(const std::string& mapping, const std::string& calib,
                                           std::shared_ptr<const Scan> target, std::shared_ptr<const Scan> source,
                                           const Pose& T_base_mapping, const Pose& guess) {
  pipeline::CalibrationDataset d;
  d.mapping_sensor = mapping;
  d.calibration_sensor = calib;
  d.T_base_mapping = T_base_mapping;
  d.T_mapping_calib_guess = guess;
  pipeline::MappingFrame keyframe;
  keyframe.kind = pipeline::FrameKind::kStoppedKeyframe;
  keyframe.keyframe_index = 0;
  keyframe.stamp_ns = target->stamp_ns;
  d.trajectory = {keyframe};
  d.mapping_clouds = {{keyframe, std::move(target)}};
  pipeline::CalibrationFrame f;
  f.pairing.keyframe_frame = 0;
  f.pairing.stopped = true;
  f.pairing.accepted = true;
  f.raw = source;
  f.deskewed = std::move(source);
  d.frames = {f};
  d.budget_full = true;
  return d;
}

// The static verdict: the lidar-lidar rules with the accumulated cloud as the one frame there is, then the
// scene's own doubts (directions it leaves free, a second basin as good as the best).
void judgeStatic(LidarLidarResult& r, const CloudPairResult& pair, const std::vector<std::string>& weak,
                 double deadline_s, double min_uniqueness) {
  VerdictOptions vo;
  vo.min_frames = 1;  // one accumulated cloud: the registrators' agreement and the inliers are the evidence
  judgeLidarLidar(r, 1, deadline_s, vo);
  if (r.verdict == Verdict::kFailed) return;
  std::vector<std::string> doubts;
  if (!weak.empty()) {
    std::string names;
    for (const auto& w : weak) names += (names.empty() ? "" : ", ") + w;
    doubts.push_back("degenerate: the scene leaves " + names +
                     " poorly constrained (information share < " + fixed(kWeakShare, 2) +
                     "): their values come from the start, not the data; add structure facing those directions");
  }
  if (pair.global && pair.global->second_score) {
    const double ratio = *pair.global->second_score / std::max(pair.global->best_score, 1e-12);
    if (ratio < min_uniqueness)
      doubts.push_back("ambiguous: the global stage's second basin scores " + fixed(ratio, 2) +
                       "x the best (needs " + fixed(min_uniqueness, 2) + "x): a symmetric scene");
  }
  if (doubts.empty()) return;
  std::string all;
  for (const auto& d : doubts) all += (all.empty() ? "" : "; ") + d;
  r.doubt = r.verdict == Verdict::kUnverified && !r.doubt.empty() ? all + "; " + r.doubt : all;
  r.verdict = Verdict::kUnverified;
}

// The pair's weak directions, less those the shared floor fixed: a tilt (a rotation axis along the floor)
// and the height (a translation across it). What the floor leaves free (yaw, along the floor) stays weak.
std::vector<std::string> weakDirections(const RegistrationInformation& info, const SharedGroundRefinement* floor) {
  std::vector<std::string> weak;
  const auto fixedByFloor = [&](const DirectionInformation& d, bool rotation) {
    if (floor == nullptr || !floor->applied) return false;
    const double along_normal = std::abs(d.direction.dot(floor->floor_normal));
    return rotation ? along_normal < 0.5 : along_normal > 0.87;  // within 30° of the floor / of its normal
  };
  for (const auto& d : info.translation)
    if (d.weak && !fixedByFloor(d, false)) weak.push_back(d.name);
  for (const auto& d : info.rotation)
    if (d.weak && !fixedByFloor(d, true)) weak.push_back(d.name);
  return weak;
}

}  // namespace

StillnessCheck checkStillness(const ScanList& scans, const config::Parameters& params) {
  const auto t0 = Clock::now();
  StillnessCheck c;
  c.limit_m = params.static_max_motion_m;
  c.limit_deg = params.static_max_motion_deg;
  if (scans.size() < 2 || scans.front() == nullptr) {
    c.seconds = since(t0);
    return c;
  }
  const SweepRegistrar first(*scans.front());
  Pose previous = Pose::Identity();  // each sweep starts from the previous one's pose: motion is smooth
  for (std::size_t k = 1; k < scans.size(); ++k) {
    if (scans[k] == nullptr) continue;
    const auto T = first.motion(*scans[k], previous);
    if (!T) continue;
    previous = *T;
    StillnessSample s;
    s.scan = k;
    s.t_s = toSeconds(scans[k]->stamp_ns - scans.front()->stamp_ns);
    s.metres = T->translation().norm();
    s.degrees = rad2deg(rotationAngleBetween(*T, Pose::Identity()));
    c.samples.push_back(s);
    if (s.metres > c.largest.metres || (s.metres == c.largest.metres && s.degrees > c.largest.degrees)) c.largest = s;
    if (!c.first_moved && (s.metres > c.limit_m || s.degrees > c.limit_deg)) c.first_moved = s;
  }
  c.still = !c.first_moved.has_value();
  if (!c.still) {
    const StillnessSample& m = *c.first_moved;
    std::ostringstream o;
    o << std::fixed << "the vehicle moved during the static capture: " << std::setprecision(2) << m.t_s
      << " s into it (sweep " << m.scan << ") the mapping lidar was " << std::setprecision(3) << m.metres << " m / "
      << std::setprecision(2) << m.degrees << " deg from where it started (limits static_max_motion_m "
      << c.limit_m << " m, static_max_motion_deg " << c.limit_deg << " deg), at most " << std::setprecision(3)
      << c.largest.metres << " m / " << std::setprecision(2) << c.largest.degrees << " deg at " << c.largest.t_s
      << " s: park the vehicle and record again";
    c.message = o.str();
  }
  c.seconds = since(t0);
  return c;
}

Scan accumulateSweeps(const ScanList& scans, double voxel) {
  registration::PointCloud all;
  Scan like;
  bool first = true;
  for (const auto& s : scans) {
    if (s == nullptr) continue;
    if (first) like.sensor_id = s->sensor_id, like.stamp_ns = s->stamp_ns, first = false;
    const auto c = registration::fromScan(*s);
    all.points.insert(all.points.end(), c.points.begin(), c.points.end());
  }
  return registration::toScan(registration::voxelDownsample(all, voxel), like);
}

StaticCalibration calibrateStatic(const StaticCapture& capture, const config::RigConfig& rig,
                                  const StaticCalibrationOptions& opt) {
  const auto t_plan = Clock::now();
  StaticCalibration out;
  CalibrationOutcome& o = out.outcome;
  o.rig_name = rig.name;
  o.base_frame = rig.roles.base_frame;
  o.mapping_sensor = rig.roles.mapping_lidar;
  o.initial_T_base_sensor = rig.initial_T_base_sensor;
  o.deadline_s = opt.deadline_s;
  const Pose T_base_mapping = rig.initial_T_base_sensor.at(rig.roles.mapping_lidar);

  out.stillness = checkStillness(capture.mapping, rig.parameters);
  o.stage_seconds.emplace_back("stillness", out.stillness.seconds);
  if (!out.stillness.still) {
    o.failure = out.stillness.message;
    return out;
  }
  if (capture.mapping.empty()) {
    o.failure = "no sweep of the mapping lidar " + rig.roles.mapping_lidar + " in the static capture";
    return out;
  }
  const auto t_acc = Clock::now();
  auto target = std::make_shared<const Scan>(accumulateSweeps(capture.mapping, kAccumulationVoxel));
  o.map_cloud = target;
  o.stage_seconds.emplace_back("accumulate", since(t_acc));
  // The floor and the structure on it under the mapping lidar, for every calibration lidar's refinement.
  const SharedGroundReference floor_reference(*target,
                                              T_base_mapping.linear().transpose() * Eigen::Vector3d::UnitZ());
  o.stage_seconds.emplace_back("shared_floor_reference", floor_reference.buildSeconds());

  // Each calibration lidar in turn, each with an equal share of what is left of the deadline less the
  // share kept for what comes after the ensembles (polish, information, floor refinement, base-lidar).
  const auto t_ll = Clock::now();
  const double ensembles_s = (1.0 - opt.later_share) * opt.deadline_s;
  for (std::size_t k = 0; k < capture.calibration.size(); ++k) {
    const auto& [sensor, scans] = capture.calibration[k];
    const Pose guess = T_base_mapping.inverse() * rig.initial_T_base_sensor.at(sensor);
    if (scans.empty()) {
      o.failure += (o.failure.empty() ? "" : "; ") + ("no sweep of " + sensor + " in the static capture");
      continue;
    }
    auto source = std::make_shared<const Scan>(accumulateSweeps(scans, kAccumulationVoxel));
    CloudPairOptions po;
    po.T_target_source_guess = guess;
    po.num_threads = opt.num_threads;
    po.exhaustive = false;
    po.deadline_covers_global = true;
    const double left = std::max(0.0, ensembles_s - since(t_plan));
    po.deadline_s = left / double(capture.calibration.size() - k);
    CloudPairResult pair = registerCloudPair(*target, *source, rig.parameters, po);
    // The ensemble's cost leaves a tilted lidar's tilt weak where the two see different floor: both
    // floors, fitted in each lidar's frame, fix tilt and height; the structure on them yaw and x/y.
    std::optional<SharedGroundRefinement> floor;
    if (pair.ok) {
      floor = floor_reference.refine(*source, pair.T_target_source);
      if (floor->applied) pair.T_target_source = floor->T_target_source;
    }
    const auto weak = weakDirections(pair.information, floor ? &*floor : nullptr);

    LidarLidarResult r = pair.ensemble;
    r.mapping_sensor = rig.roles.mapping_lidar;
    r.calibration_sensor = sensor;
    r.ok = pair.ok;
    r.failure = pair.ok ? "" : pair.failure;
    r.deadline_share_s = po.deadline_s;
    r.T_mapping_calib_guess = guess;
    r.T_mapping_calib = pair.ok ? pair.T_target_source : guess;
    r.initial_score = pair.guess_score;
    r.final_score = pair.final_score;
    r.seconds = pair.seconds;
    judgeStatic(r, pair, weak, opt.deadline_s, opt.min_uniqueness);

    o.datasets.push_back(staticDataset(rig.roles.mapping_lidar, sensor, target, source, T_base_mapping, guess));
    o.lidars.push_back(std::move(r));
    o.input_summary.emplace_back(sensor + "_sweeps", std::to_string(scans.size()));
    o.input_summary.emplace_back(sensor + "_overlap", fixed(pair.source_overlap, 3));
    std::string weak_names;
    for (const auto& w : weak) weak_names += (weak_names.empty() ? "" : " ") + w;
    o.input_summary.emplace_back(sensor + "_weak_directions", weak_names.empty() ? "none" : weak_names);
    if (floor) {
      o.input_summary.emplace_back(
          sensor + "_shared_floor",
          floor->applied ? "tilt " + fixed(floor->tilt_correction_deg, 3) + " deg, height " +
                               fixed(100 * floor->height_correction_m, 2) + " cm, yaw " +
                               fixed(floor->yaw_correction_deg, 3) + " deg, along the floor " +
                               fixed(100 * floor->planar_correction_m, 2) + " cm (" +
                               std::to_string(floor->source_floor_points) + " / " +
                               std::to_string(floor->target_floor_points) + " floor points)"
                         : "not applied: " + floor->note);
      o.stage_seconds.emplace_back(sensor + "_shared_floor", floor->seconds);
    }
    if (pair.global && pair.global->second_score)
      o.input_summary.emplace_back(sensor + "_second_basin_ratio",
                                   fixed(*pair.global->second_score / std::max(pair.global->best_score, 1e-12), 2));
    out.pairs.emplace_back(sensor, std::move(pair));
  }
  o.stage_seconds.emplace_back("lidar_lidar", since(t_ll));

  // Base-lidar from the ground under the mapping lidar (its accumulated cloud, its own frame).
  const auto t_base = Clock::now();
  if (rig.parameters.calibrate_base_frame) {
    std::vector<Eigen::Vector3d> points;
    points.reserve(target->size());
    for (std::size_t i = 0; i < target->size(); ++i) points.emplace_back(target->x[i], target->y[i], target->z[i]);
    // Parked, the lidar never sees the ground under the vehicle (the footprint crop box of a drive): the
    // box grows by kGroundMargin around it, the floor the lidar does see.
    config::Parameters p = rig.parameters;
    p.base_lidar_crop_box_min_x -= kGroundMargin;
    p.base_lidar_crop_box_min_y -= kGroundMargin;
    p.base_lidar_crop_box_max_x += kGroundMargin;
    p.base_lidar_crop_box_max_y += kGroundMargin;
    o.base = calibrateBaseLidar(points, T_base_mapping, p);
  } else {
    o.base_skipped = "calibrate_base_frame: false in the rig's parameters";
  }
  o.stage_seconds.emplace_back("base_lidar", since(t_base));
  return out;
}

}  // namespace rigcal::calib
