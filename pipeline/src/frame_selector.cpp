#include "rigcal/pipeline/frame_selector.hpp"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <sstream>

namespace rigcal::pipeline {

double pcaInformation(const Scan& cloud) {
  if (cloud.size() < 3) return 0.0;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < cloud.size(); ++i) mean += Eigen::Vector3d(cloud.x[i], cloud.y[i], cloud.z[i]);
  mean /= double(cloud.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3d d = Eigen::Vector3d(cloud.x[i], cloud.y[i], cloud.z[i]) - mean;
    cov += d * d.transpose();
  }
  cov /= double(cloud.size());
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(cov, Eigen::EigenvaluesOnly);
  return std::sqrt(std::max(0.0, solver.eigenvalues()(0)));
}

namespace {
std::string fmt(double v) {
  std::ostringstream s;
  s.precision(3);
  s << v;
  return s.str();
}
}  // namespace

Selection selectFrames(const std::vector<SelectionCandidate>& candidates,
                       const std::vector<int>& lost_keyframe_indices, const config::Parameters& params) {
  Selection result;
  std::vector<const SelectionCandidate*> pool;
  for (const auto& c : candidates) {
    const auto near_lost = std::find_if(lost_keyframe_indices.begin(), lost_keyframe_indices.end(), [&](int lost) {
      return std::abs(c.keyframe_index - lost) <= params.dense_pointcloud_num_keyframes;
    });
    if (near_lost != lost_keyframe_indices.end()) {
      result.rejected.push_back({c.id, "within " + std::to_string(params.dense_pointcloud_num_keyframes) +
                                           " keyframes of lost keyframe " + std::to_string(*near_lost)});
    } else if (c.information < params.calibration_min_pca_eigenvalue) {
      result.rejected.push_back({c.id, "PCA information " + fmt(c.information) + " < " +
                                           fmt(params.calibration_min_pca_eigenvalue) + " (too flat)"});
    } else {
      pool.push_back(&c);
    }
  }
  const bool by_planes = params.calibration_frame_ranking != "pca";
  registration::PointToPlaneInformation chosen_planes;  // summed over the chosen frames
  // The rank of a candidate as the next frame; higher first, then by PCA information, then by id.
  auto rank = [&](const SelectionCandidate* c) {
    if (!by_planes) return 0.0;
    registration::PointToPlaneInformation with = chosen_planes;
    with += c->planes;
    return with.weakestRelative();
  };
  while (!pool.empty()) {
    if (int(result.selected.size()) >= params.lidar_calibration_max_frames) {
      for (const SelectionCandidate* c : pool)
        result.rejected.push_back({c->id, "frame budget full (lidar_calibration_max_frames = " +
                                              std::to_string(params.lidar_calibration_max_frames) + ")"});
      break;
    }
    const SelectionCandidate* best = nullptr;
    double best_rank = 0.0;
    for (const SelectionCandidate* c : pool) {
      const double r = rank(c);
      if (best == nullptr || r > best_rank ||
          (r == best_rank && (c->information > best->information ||
                              (c->information == best->information && c->id < best->id)))) {
        best = c;
        best_rank = r;
      }
    }
    result.selected.push_back(best->id);
    chosen_planes += best->planes;
    std::vector<const SelectionCandidate*> rest;
    for (const SelectionCandidate* c : pool) {
      if (c == best) continue;
      const double gap = std::abs(best->path_length - c->path_length);
      if (gap < params.calibration_min_distance_between_frames)
        result.rejected.push_back({c->id, "only " + fmt(gap) + " m of path from selected frame " + std::to_string(best->id)});
      else
        rest.push_back(c);
    }
    pool = std::move(rest);
  }
  return result;
}

}  // namespace rigcal::pipeline
