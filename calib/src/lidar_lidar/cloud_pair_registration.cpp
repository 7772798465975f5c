#include "rigcal/calib/lidar_lidar/cloud_pair_registration.hpp"

#include <chrono>
#include <iomanip>
#include <memory>
#include <sstream>

#include "rigcal/calib/outputs/calibration_outcome.hpp"
#include "rigcal/calib/lidar_lidar/calibration_source.hpp"
#include "rigcal/calib/outputs/cloud_writers.hpp"
#include "rigcal/calib/outputs/overview_png_writer.hpp"
#include "rigcal/core/atomic_file.hpp"
#include "rigcal/registration/icp.hpp"
#include "rigcal/registration/voxel_grid.hpp"
#include "scan_points.hpp"

namespace rigcal::calib {
namespace {

using detail::finitePoints;

using Clock = std::chrono::steady_clock;

// The pair as the lidar-lidar calibration's input: the target is the only mapping cloud (at a keyframe
// with the identity pose), the source the only calibration frame, taken while standing (no deskew).
pipeline::CalibrationDataset pairDataset(std::shared_ptr<const Scan> target, std::shared_ptr<const Scan> source,
                                         const Pose& guess) {
  pipeline::CalibrationDataset d;
  d.mapping_sensor = "target";
  d.calibration_sensor = "source";
  d.T_mapping_calib_guess = guess;
  pipeline::MappingFrame keyframe;
  keyframe.kind = pipeline::FrameKind::kKeyframe;
  keyframe.keyframe_index = 0;
  pipeline::MappingFrame next = keyframe;  // the trajectory needs two poses: the same place, a moment later
  next.sequence = 1;
  next.stamp_ns = 1;
  next.kind = pipeline::FrameKind::kStopped;
  next.keyframe_index = -1;
  d.trajectory = {keyframe, next};
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

// Share of `query` (mapped by T) with a `cloud` point within `distance`; `within` (optional) keeps only the
// query points that far from `centre` (the other sensor's reach).
double overlapShare(const registration::KdTree& tree, const std::vector<Eigen::Vector3d>& query, const Pose& T,
                    double distance, const Eigen::Vector3d& centre = Eigen::Vector3d::Zero(),
                    double within = std::numeric_limits<double>::infinity()) {
  std::size_t considered = 0, near = 0;
  for (const auto& p : query) {
    const Eigen::Vector3d q = T * p;
    if ((q - centre).norm() > within) continue;
    ++considered;
    registration::Neighbor nb;
    if (tree.nearest(q.homogeneous(), distance * distance, &nb)) ++near;
  }
  return considered == 0 ? 0.0 : double(near) / double(considered);
}

std::vector<Eigen::Vector3d> toVectors(const registration::PointCloud& c) {
  std::vector<Eigen::Vector3d> v;
  v.reserve(c.size());
  for (const auto& p : c.points) v.push_back(p.head<3>());
  return v;
}

}  // namespace

CloudPairResult registerCloudPair(const Scan& target_scan, const Scan& source_scan, const config::Parameters& params_in,
                                  const CloudPairOptions& opt) {
  const auto t0 = Clock::now();
  CloudPairResult r;
  r.T_target_source_guess = opt.T_target_source_guess;
  r.T_target_source = opt.T_target_source_guess;
  const auto target_points = finitePoints(target_scan), source_points = finitePoints(source_scan);
  r.target_points = target_points.size();
  r.source_points = source_points.size();
  const auto finish = [&](std::string failure) {
    r.failure = std::move(failure);
    r.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    return r;
  };
  if (target_points.empty()) return finish("the target cloud has no finite points");
  if (source_points.empty()) return finish("the source cloud has no finite points");

  config::Parameters params = params_in;
  params.lidar_calibration_min_frames = 1;  // one pair is the whole dataset

  // The yardstick the ensemble uses, built here once more for the guess's score, overlap and information.
  registration::TargetOptions to;
  to.normals_and_covariances = true;
  to.num_threads = opt.num_threads;
  const registration::Target target(
      registration::voxelDownsample(registration::fromPoints(target_points), params.leaf_size_dense_map), to);
  SourceOptions so;
  so.covariances = false;
  const registration::PointCloud source = buildSource(source_scan, params, so);
  if (source.size() < 10) {
    r.not_enough_data = true;
    return finish("the source cloud has " + std::to_string(source.size()) + " points within the calibration range " +
                  "(min_calibration_range .. max_calibration_range)");
  }
  const double d_eval = params.calibration_eval_max_corr_distance;
  r.guess_score = scoreFrame(target, source, opt.T_target_source_guess, d_eval, opt.num_threads);

  Pose start = opt.T_target_source_guess;
  if (opt.global_search) {
    r.global = globalSearch(target_points, source_points, opt.T_target_source_guess, opt.global);
    // The search's best replaces the guess only when the ensemble's own score agrees it is better.
    const auto s = scoreFrame(target, source, r.global->T_target_source, d_eval, opt.num_threads);
    if (s.betterThan(r.guess_score)) start = r.global->T_target_source;
  }

  const auto source_voxels = toVectors(registration::voxelDownsample(source, 0.1));
  const double start_overlap = overlapShare(target.tree(), source_voxels, start, opt.overlap_distance);
  if (start_overlap < opt.min_overlap) {
    r.not_enough_data = true;
    r.source_overlap = start_overlap;
    std::ostringstream msg;
    msg << "the clouds do not overlap: " << std::fixed << std::setprecision(1) << 100 * start_overlap
        << " % of the source within " << opt.overlap_distance << " m of the target"
        << (opt.global_search ? " at the global search's best pose" : " at the initial guess (try without --local)");
    return finish(msg.str());
  }

  auto target_ptr = std::make_shared<const Scan>(target_scan);
  auto source_ptr = std::make_shared<const Scan>(source_scan);
  const auto dataset = pairDataset(target_ptr, source_ptr, start);
  LidarLidarOptions lo;
  lo.num_threads = opt.num_threads;
  lo.redeskew = false;  // standing still: nothing to deskew
  lo.exhaustive = opt.exhaustive;
  const double spent = std::chrono::duration<double>(Clock::now() - t0).count();
  const double ensemble_s =
      opt.deadline_covers_global ? std::max(0.1 * opt.deadline_s, opt.deadline_s - spent) : opt.deadline_s;
  const auto deadline = registration::Deadline::after(
      std::chrono::duration_cast<registration::Deadline::Clock::duration>(std::chrono::duration<double>(ensemble_s)));
  r.ensemble = calibrateLidarLidar(dataset, params, deadline, lo);
  // The ensemble keeps its start when nothing beats it: the start (the global stage's) is then the result.
  r.T_target_source = r.ensemble.ok ? r.ensemble.T_mapping_calib : start;
  CalibrationScore final_score = scoreFrame(target, source, r.T_target_source, d_eval, opt.num_threads);
  // Polish: the ensemble's registrations stop at their convergence tolerance, which in a weakly constrained
  // direction (yaw over flat ground) leaves the result where the start put it. One point-to-plane ICP over
  // all points, run to a 1e-6 tolerance, takes every start to the same minimum; kept only if it scores better.
  {
    registration::IcpParams p;
    p.method = registration::IcpMethod::kPointToPlane;
    p.max_correspondence_distance = params.max_corr_dist_fine;
    p.max_iterations = 200;
    p.transformation_epsilon = 1e-6;
    p.rotation_epsilon = 1e-7;
    p.coarse_to_fine = false;
    p.check_degeneracy = false;  // reported below instead (information per direction)
    p.num_threads = opt.num_threads;
    const auto polished = registration::alignIcp(target, source, r.T_target_source, p);
    if (polished.T_target_source.matrix().allFinite()) {
      const auto s = scoreFrame(target, source, polished.T_target_source, d_eval, opt.num_threads);
      if (s.betterThan(final_score)) {
        final_score = s;
        r.T_target_source = polished.T_target_source;
      }
    }
  }
  r.final_score = final_score;

  // Overlap both ways, and the information per direction at the result.
  r.source_overlap = overlapShare(target.tree(), source_voxels, r.T_target_source, opt.overlap_distance);
  registration::PointCloud placed = registration::transformed(registration::voxelDownsample(source, 0.1), r.T_target_source);
  const registration::KdTree placed_tree(placed.points);
  double reach = 0.0;
  for (const auto& p : source.points) reach = std::max(reach, p.head<3>().norm());
  r.target_overlap = overlapShare(placed_tree, toVectors(target.cloud()), Pose::Identity(), opt.overlap_distance,
                                  r.T_target_source.translation(), reach);
  r.information = registrationInformation(target, source, r.T_target_source, 2 * d_eval);

  if (r.source_overlap < opt.min_overlap) {
    r.not_enough_data = true;
    std::ostringstream msg;
    msg << "the clouds do not overlap: " << std::fixed << std::setprecision(1) << 100 * r.source_overlap
        << " % of the source within " << opt.overlap_distance << " m of the target after registration";
    return finish(msg.str());
  }
  if (final_score.inlier_ratio < opt.min_inlier_ratio) {
    r.not_enough_data = true;
    std::ostringstream msg;
    msg << "the clouds do not overlap: after registration only " << std::fixed << std::setprecision(1)
        << 100 * final_score.inlier_ratio << " % of the source lies within " << std::setprecision(2) << d_eval
        << " m of the target (a registration needs " << std::setprecision(0) << 100 * opt.min_inlier_ratio << " %)";
    return finish(msg.str());
  }
  if (!final_score.betterThan(r.guess_score) && !r.ensemble.ok && !r.global) {
    return finish("registration did not improve on the initial guess: " + r.ensemble.failure);
  }
  r.ok = true;
  return finish("");
}

namespace {
void writeRegistrationYamlTo(std::ostream& out, const CloudPairResult& r, const std::string& target_name,
                             const std::string& source_name) {
  const auto pose = [&](const char* indent, const Pose& T) {
    const XyzRpy v = toXyzRpy(T);
    out << std::fixed << std::setprecision(6) << indent << "x: " << v.x << "\n"
        << indent << "y: " << v.y << "\n" << indent << "z: " << v.z << "\n"
        << indent << "roll: " << v.roll << "\n" << indent << "pitch: " << v.pitch << "\n"
        << indent << "yaw: " << v.yaw << "\n";
  };
  out << "# rigcal register: T_target_source maps source points into the target frame\n"
      << "# x y z (m) roll pitch yaw (rad), R = Rz(yaw)*Ry(pitch)*Rx(roll), as calibration.yaml\n"
      << "target: " << target_name << "\nsource: " << source_name << "\nok: " << (r.ok ? "true" : "false") << "\n";
  if (!r.failure.empty()) out << "failure: \"" << r.failure << "\"\n";
  out << "T_target_source:\n";
  pose("  ", r.T_target_source);
  out << "T_target_source_matrix:\n";
  for (int i = 0; i < 4; ++i) {
    out << "  - [";
    for (int j = 0; j < 4; ++j) out << (j ? ", " : "") << std::setprecision(9) << r.T_target_source.matrix()(i, j);
    out << "]\n";
  }
  out << "initial_T_target_source:\n";
  pose("  ", r.T_target_source_guess);
  out << std::setprecision(6) << "score:  # mean of min(d^2, d_max^2) over the source points (m^2), lower is better\n"
      << "  initial: " << r.guess_score.value << "\n  initial_inlier_ratio: " << r.guess_score.inlier_ratio << "\n"
      << "  final: " << r.final_score.value << "\n  final_inlier_ratio: " << r.final_score.inlier_ratio
      << "\n  final_rmse_m: " << r.final_score.rmse << "\n";
  if (r.global) {
    const auto& g = *r.global;
    out << "global_search:\n  ground_planes_used: " << (g.ground_used ? "true" : "false") << "\n";
    if (!g.ground_note.empty()) out << "  ground_note: \"" << g.ground_note << "\"\n";
    out << "  best_score: " << g.best_score << "\n  best_inlier_ratio: " << g.best_inlier_ratio << "\n";
    if (g.second_score) {
      out << "  second_basin_score: " << *g.second_score << "\n  uniqueness: " << *g.second_score / std::max(g.best_score, 1e-12)
          << "  # second-best basin's score / best's: near 1 = ambiguous\n";
    }
    out << "  poses_scored: " << g.poses_scored << "\n  seconds: " << g.seconds << "\n";
  }
  out << "ensemble:\n  registrations: " << r.ensemble.runs.size() << "\n  candidates: " << r.ensemble.candidates.size()
      << "\n  deadline_reached: " << (r.ensemble.deadline_reached ? "true" : "false") << "\n  seconds: " << r.ensemble.seconds
      << "\n";
  out << "overlap:\n  source_share: " << r.source_overlap << "\n  target_share: " << r.target_overlap << "\n"
      << "information:  # Hessian eigenvalue shares per direction (target frame); weak < " << kWeakShare << "\n"
      << "  correspondences: " << r.information.correspondences << "\n";
  for (const auto* block : {&r.information.translation, &r.information.rotation}) {
    out << (block == &r.information.translation ? "  translation:\n" : "  rotation:\n");
    for (const auto& d : *block)
      out << "    - {axis: " << d.name << ", direction: [" << d.direction.x() << ", " << d.direction.y() << ", "
          << d.direction.z() << "], eigenvalue: " << d.eigenvalue << ", share: " << d.share
          << ", weak: " << (d.weak ? "true" : "false") << "}\n";
  }
  out << "weak_directions: [";
  const auto weak = r.information.weakDirections();
  for (std::size_t k = 0; k < weak.size(); ++k) out << (k ? ", " : "") << weak[k];
  out << "]\nseconds: " << r.seconds << "\n";
}
}  // namespace

void writeRegistrationYaml(const std::filesystem::path& path, const CloudPairResult& r, const std::string& target_name,
                           const std::string& source_name) {
  writeFileAtomically(path, [&](std::ostream& out) { writeRegistrationYamlTo(out, r, target_name, source_name); });
}

void writeRegistrationClouds(const std::filesystem::path& dir, const Scan& target, const Scan& source,
                             const CloudPairResult& r) {
  auto target_ptr = std::make_shared<const Scan>(target);
  const auto dataset = pairDataset(target_ptr, std::make_shared<const Scan>(source), r.T_target_source_guess);
  writeCloudPcd(dir / "target.pcd", finitePoints(target));
  writeCloudPcd(dir / "source_before.pcd", calibrationCloudInMap(dataset, r.T_target_source_guess));
  writeCloudPcd(dir / "source_after.pcd", calibrationCloudInMap(dataset, r.T_target_source));
  CalibrationOutcome o;
  o.rig_name = "register";
  o.mapping_sensor = "target";
  o.map_cloud = target_ptr;
  o.datasets = {dataset};
  LidarLidarResult shown = r.ensemble;
  shown.calibration_sensor = "source";
  shown.ok = r.ok;
  shown.T_mapping_calib = r.T_target_source;
  o.lidars = {shown};
  writeOverviewPng(dir / "overlay.png", o);
}

}  // namespace rigcal::calib
