#include "rigcal/calib/lidar_lidar/calibration_score.hpp"

#include <algorithm>

#include "rigcal/registration/evaluator.hpp"

namespace rigcal::calib {
namespace {

CalibrationScore fromEvaluation(const registration::Evaluation& e) {
  CalibrationScore s;
  s.value = e.fitness;
  s.rmse = e.rmse;
  s.inlier_ratio = e.inlier_ratio;
  s.points = e.points;
  s.inliers = e.inliers;
  return s;
}

}  // namespace

CalibrationScore scoreFrame(const registration::Target& target, const registration::PointCloud& source,
                            const Pose& T_mapping_calib, double max_distance, int num_threads) {
  return fromEvaluation(registration::evaluate(target, source, T_mapping_calib, max_distance, num_threads));
}

CalibrationScore scoreAllFrames(const std::vector<registration::SourceTarget>& frames, const Pose& T_mapping_calib,
                                double max_distance, std::size_t stride, int num_threads) {
  if (stride <= 1) return fromEvaluation(registration::evaluate(frames, T_mapping_calib, max_distance, num_threads));
  // Thinned copies of the sources (cheap next to the nearest-neighbour queries they save).
  std::vector<registration::PointCloud> thinned(frames.size());
  std::vector<registration::SourceTarget> pairs(frames.size());
  for (std::size_t f = 0; f < frames.size(); ++f) {
    const auto& pts = frames[f].source->points;
    thinned[f].points.reserve(pts.size() / stride + 1);
    for (std::size_t i = 0; i < pts.size(); i += stride) thinned[f].points.push_back(pts[i]);
    pairs[f] = {&thinned[f], frames[f].target};
  }
  return fromEvaluation(registration::evaluate(pairs, T_mapping_calib, max_distance, num_threads));
}

std::size_t scoreStride(const std::vector<registration::SourceTarget>& frames, std::size_t max_points) {
  std::size_t total = 0;
  for (const auto& f : frames) total += f.source->size();
  if (max_points == 0 || total <= max_points) return 1;
  return (total + max_points - 1) / max_points;
}

}  // namespace rigcal::calib
